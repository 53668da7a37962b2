#version 450 core
// Thin quads along every elemental-image border (DESIGN.md §3 step 2), for the second pass of
// elemental.frag: only pixels whose aperture may straddle a border (and the lit block's edge) get
// the per-lens area split, so the first pass can stay one tap per pixel. The borders are the lines
// q = k + ½ of the lens lattice projected onto the display; quad i < u_lenses.x + 1 is the vertical
// border k = u_first_lens.x - ½ + i, the others are horizontal. Six vertices per quad.

#include "mapping.glsl"

// A (sub-)aperture straddles a border when its centre is within half a pixel of it, measured across
// the border (area_sample takes apertures square in the lattice's frame). A little more than that
// covers every such pixel centre and almost nothing else: the area split is the costly shader.
const float half_width_px = 0.55;

void main() {
  const int quad = gl_VertexID / 6, corner = gl_VertexID % 6;
  const vec2 lo = vec2(u_first_lens) - 0.5, hi = vec2(u_first_lens + u_lenses) - 0.5;
  vec2 a, b;
  if (quad <= u_lenses.x) {
    const float x = lo.x + float(quad);
    a = vec2(x, lo.y), b = vec2(x, hi.y);
  } else {
    const float y = lo.y + float(quad - u_lenses.x - 1);
    a = vec2(lo.x, y), b = vec2(hi.x, y);
  }
  vec2 p0 = lattice_to_pixel(a), p1 = lattice_to_pixel(b);
  const vec2 along = normalize(p1 - p0), across = vec2(-along.y, along.x) * half_width_px;
  p0 -= along * half_width_px, p1 += along * half_width_px;
  // Two triangles: (p0-, p1-, p1+), (p0-, p1+, p0+).
  const int index[6] = int[6](0, 1, 2, 0, 2, 3);
  const vec2 corners[4] = vec2[4](p0 - across, p1 - across, p1 + across, p0 + across);
  const vec2 pixel = corners[index[corner]];
  gl_Position = vec4(pixel / u_panel * 2.0 - 1.0, 0.0, 1.0);
}
