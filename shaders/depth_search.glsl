// The depth-aware composite's search (optics/depth.hpp, DisparitySurface::hit, the same search in
// float): each ray shows the view where it meets the content's surface rather than the flat screen.
// Included by elemental.frag (NELF_DEPTH, NELF_DEPTH_MAP, NELF_DEPTH_HITS) and elemental_depth_lookup.frag.
layout(binding = 2) uniform sampler2D u_disparity;  // R32F: δ / W per map texel, unknown ones filled
layout(location = 1) uniform vec2 u_parallax_gain;  // uv shift per mm of pupil crossing per unit of δ / W
layout(location = 2) uniform vec2 u_disparity_range;  // back (smallest), front (largest) δ / W
layout(location = 3) uniform float u_pupil_per_lens;  // d_e / d_l: chief ray's pupil crossing = c − (s − c) · this
const int depth_search_steps = 24;                   // optics/depth.hpp: depth_search_steps
const int depth_search_bisections = 3;               // and depth_search_bisections

float surface_disparity(vec2 uv) {
  const ivec2 size = textureSize(u_disparity, 0);
  return texelFetch(u_disparity, clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1), 0).r;
}

// The δ / W of the front-most crossing of the ray (meeting the flat screen at flat_uv, shifted by
// gain per unit of δ / W) with the surface.
float surface_hit(vec2 flat_uv, vec2 gain) {
  const float back = u_disparity_range.x, front = u_disparity_range.y;
  if (!(front > back) || surface_disparity(flat_uv + gain * front) >= front) return front;
  float hit = back, before = front;
  // optics/depth.hpp: depth_search_steps_for the texels the ray crosses.
  const vec2 size = vec2(textureSize(u_disparity, 0));
  const float extent = (front - back) * max(abs(gain.x) * size.x, abs(gain.y) * size.y);
  const float wanted = ceil(2.0 * extent);
  const int steps = wanted >= float(depth_search_steps) ? depth_search_steps : wanted <= 2.0 ? 2 : int(wanted);
  for (int i = 1; i <= depth_search_steps; ++i) {  // a constant bound (llvmpipe), left at `steps`
    if (i > steps) break;
    const float d = front - (front - back) * float(i) / float(steps);
    if (surface_disparity(flat_uv + gain * d) >= d) {
      hit = d;
      break;
    }
    before = d;
  }
  for (int k = 0; k < depth_search_bisections; ++k) {
    const float mid = 0.5 * (hit + before);
    if (surface_disparity(flat_uv + gain * mid) >= mid)
      hit = mid;
    else
      before = mid;
  }
  return hit;
}

// Where that ray shows the view.
vec2 surface_uv(vec2 flat_uv, vec2 gain) { return flat_uv + gain * surface_hit(flat_uv, gain); }
