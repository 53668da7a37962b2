#version 450 core
// Footprint prefilter, step 2 (DESIGN.md §4), one axis per pass: a box of width u_box_width view
// texels centred on each output sample, output samples every u_out_spacing view texels. The input
// holds cells of u_cell_size view texels (the reduced view, or the output of the first pass);
// each cell is weighted by its overlap with the box, so the filter is exact for any fraction.
// Beyond the view's edge the edge cells repeat, like the reference's clamped bilinear taps.

uniform sampler2D u_input;
uniform int u_axis;           // 0: filter along x, 1: along y
uniform float u_cell_size;    // view texels per input texel along the axis
uniform float u_out_spacing;  // view texels per output texel along the axis
uniform float u_box_width;    // view texels

out vec4 colour;

void main() {
  const ivec2 out_texel = ivec2(floor(gl_FragCoord.xy));
  const int count = textureSize(u_input, 0)[u_axis];
  const float centre = (float(out_texel[u_axis]) + 0.5) * u_out_spacing;
  const float lo = centre - 0.5 * u_box_width, hi = centre + 0.5 * u_box_width;
  const int first = int(floor(lo / u_cell_size)), last = int(floor(hi / u_cell_size));
  vec4 sum = vec4(0.0);
  for (int i = first; i <= last; ++i) {
    const float overlap = min(float(i + 1) * u_cell_size, hi) - max(float(i) * u_cell_size, lo);
    ivec2 texel = out_texel;
    texel[u_axis] = clamp(i, 0, count - 1);
    sum += max(overlap, 0.0) * texelFetch(u_input, texel, 0);
  }
  colour = sum / u_box_width;
}
