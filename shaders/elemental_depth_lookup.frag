#version 450 core
// Pass 1 of the depth-aware composite from a depth coordinate map (elemental.frag built with
// NELF_DEPTH_MAP, rendered once per eye and view geometry): the pixel's flat-screen coordinate and
// pupil crossing are fetched rather than worked out, then the ray is searched for where it meets the
// content (depth_search.glsl) and the view tapped there, as elemental.frag with NELF_DEPTH does.
// The crossing's δ / W goes to u_hits too: the border strips (elemental.frag, NELF_DEPTH_HITS) take
// their depth from it rather than searching again.

layout(binding = 0) uniform sampler2D u_view;  // the footprint-prefiltered view (black margin)
layout(binding = 1) uniform sampler2D u_map;   // RGBA32F, panel-sized: screen uv, pupil crossing (mm)
layout(binding = 0, r32f) uniform writeonly image2D u_hits;  // panel-sized: each pixel's crossing, δ / W
// mapping.glsl: u_region_origin and the texture transform.
#include "mapping.glsl"
#include "depth_search.glsl"

out vec4 colour;

void main() {
  // One path for every pixel: llvmpipe runs both sides of a branch under a mask, so an early return
  // for the display's black pixels would only add a second image store.
  const ivec2 pixel = ivec2(gl_FragCoord.xy - u_region_origin);
  const vec4 ray = texelFetch(u_map, pixel, 0);
  const bool black = ray.x < -1.0e8;  // a black pixel of the display
  const vec2 gain = ray.zw * u_parallax_gain;
  const float hit = surface_hit(ray.xy, gain);
  imageStore(u_hits, pixel, vec4(hit));
  const vec2 uv = ray.xy + gain * hit;
  const bool outside = any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)));
  colour = vec4(black || (u_cut_outside != 0 && outside)
                    ? vec3(0.0)
                    : textureLod(u_view, uv * u_texture_scale + u_texture_offset, 0.0).rgb,
                1.0);
}
