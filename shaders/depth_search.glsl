// The depth-aware composite's search (optics/depth.hpp, DisparitySurface::hit, the same search in
// float): each ray shows the view where it meets the content's surface rather than the flat screen.
// Included by elemental.frag (NELF_DEPTH, NELF_DEPTH_MAP, NELF_DEPTH_HITS) and elemental_depth_lookup.frag.
layout(binding = 2) uniform sampler2D u_disparity;  // R32F: δ / W per map texel, unknown ones filled
layout(location = 1) uniform vec2 u_parallax_gain;  // uv shift per mm of pupil crossing per unit of δ / W
layout(location = 2) uniform vec2 u_disparity_range;  // back (smallest), front (largest) δ / W
layout(location = 3) uniform float u_pupil_per_lens;  // d_e / d_l: chief ray's pupil crossing = c − (s − c) · this
layout(binding = 4) uniform sampler2D u_front_bound;  // R32F: DisparitySurface::front_bounds
const int depth_search_texels = 48;                  // optics/depth.hpp: depth_search_texels
const int depth_bound_tile = 8;                      // optics/depth.hpp: depth_bound_tile

// The δ / W of the front-most crossing of the ray (meeting the flat screen at flat_uv, shifted by
// gain per unit of δ / W) with the surface: the ray walks the map's texels from the front of the
// range to its back; in a texel of value v that it enters at δ / W = a and leaves at b < a, it is at
// or behind the surface from v down, so it crosses there (at min(v, a)) when v >= b. One fetch a
// texel crossed; steps of half a texel and a bisection of the crossing one took three times as
// many. The walk starts where the ray falls to the front bound of the tile it starts in, or has
// moved depth_bound_tile − 1 texels along an axis (past that the bound may not hold), whichever is
// first.
float surface_hit(vec2 flat_uv, vec2 gain) {
  const float back = u_disparity_range.x, front = u_disparity_range.y;
  if (!(front > back)) return front;
  const ivec2 size = textureSize(u_disparity, 0);
  const float range = front - back;
  const vec2 start = (flat_uv + gain * front) * vec2(size);  // texel coordinate at the front
  const vec2 v = -gain * vec2(size);                          // texels per unit of (front − δ / W)
  const ivec2 tile = clamp(ivec2(floor(start)), ivec2(0), size - 1) / depth_bound_tile;
  const float bound = texelFetch(u_front_bound, tile, 0).r;
  const float fastest = max(max(abs(v.x), abs(v.y)), 1.0e-30);
  float t = min(min(front - bound, float(depth_bound_tile - 1) / fastest), range);
  const vec2 p = start + v * t;
  ivec2 texel = ivec2(floor(p));
  const ivec2 step_ = ivec2(sign(v));
  const vec2 delta = 1.0 / max(abs(v), vec2(1.0e-30));
  vec2 next = t + mix(p - floor(p), floor(p) + 1.0 - p, greaterThan(v, vec2(0.0))) * delta;
  for (int i = 0; i < depth_search_texels; ++i) {
    const float t_next = min(min(next.x, next.y), range);
    const float value = texelFetch(u_disparity, clamp(texel, ivec2(0), size - 1), 0).r;
    const float leave = t_next >= range ? back : front - t_next;
    if (value >= leave) return min(value, front - t);
    if (t_next >= range) break;
    if (next.x < next.y) {
      texel.x += step_.x;
      t = next.x;
      next.x += delta.x;
    } else {
      texel.y += step_.y;
      t = next.y;
      next.y += delta.y;
    }
  }
  return back;
}

// Where that ray shows the view.
vec2 surface_uv(vec2 flat_uv, vec2 gain) { return flat_uv + gain * surface_hit(flat_uv, gain); }
