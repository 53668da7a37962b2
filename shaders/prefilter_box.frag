#version 450 core
// Footprint prefilter, step 2 (DESIGN.md §4), one axis per pass: a box of width u_box_width view
// texels centred on each output sample, output samples every u_out_spacing view texels. The input
// holds cells of u_cell_size view texels (the reduced view, or the output of the first pass);
// each cell is weighted by its overlap with the box, so the filter is exact for any fraction.
// The output grid extends u_out_origin view texels beyond the view's edges (negative): the view
// is black outside [0, u_view_extent], as on the reference's screen, so a pixel whose footprint
// straddles the screen's edge gets the right mix of picture and black.

layout(binding = 0) uniform sampler2D u_input;
layout(location = 0) uniform int u_axis;           // 0: filter along x, 1: along y
layout(location = 1) uniform float u_cell_size;    // view texels per input texel along the axis
layout(location = 2) uniform float u_out_spacing;  // view texels per output texel along the axis
layout(location = 3) uniform float u_box_width;    // view texels
layout(location = 4) uniform float u_out_origin;   // view-texel position of the output grid's first edge (<= 0)
layout(location = 5) uniform float u_view_extent;  // the view's size along the axis, in view texels

out vec4 colour;

void main() {
  const ivec2 out_texel = ivec2(floor(gl_FragCoord.xy));
  const int count = textureSize(u_input, 0)[u_axis];
  const float centre = u_out_origin + (float(out_texel[u_axis]) + 0.5) * u_out_spacing;
  const float lo = centre - 0.5 * u_box_width, hi = centre + 0.5 * u_box_width;
  // Only the part of the window on the view contributes; the rest is black.
  const float view_lo = max(lo, 0.0), view_hi = min(hi, u_view_extent);
  const int first = max(int(floor(view_lo / u_cell_size)), 0);
  const int last = min(int(floor(view_hi / u_cell_size)), count - 1);
  vec4 sum = vec4(0.0);
  for (int i = first; i <= last; ++i) {
    const float overlap = min(float(i + 1) * u_cell_size, view_hi) - max(float(i) * u_cell_size, view_lo);
    ivec2 texel = out_texel;
    texel[u_axis] = i;
    sum += max(overlap, 0.0) * texelFetch(u_input, texel, 0);
  }
  colour = vec4(sum.rgb / u_box_width, 1.0);
}
