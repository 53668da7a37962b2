#version 450 core
// Pass 1 of the depth-aware composite from a depth coordinate map (elemental.frag built with
// NELF_DEPTH_MAP, rendered once per eye and view geometry): the pixel's flat-screen coordinate and
// pupil crossing are fetched rather than worked out, then the ray is searched for where it meets the
// content (depth_search.glsl) and the view tapped there, as elemental.frag with NELF_DEPTH does.

layout(binding = 0) uniform sampler2D u_view;  // the footprint-prefiltered view (black margin)
layout(binding = 1) uniform sampler2D u_map;   // RGBA32F, panel-sized: screen uv, pupil crossing (mm)
// mapping.glsl: u_region_origin and the texture transform.
#include "mapping.glsl"
#include "depth_search.glsl"

out vec4 colour;

void main() {
  const vec4 ray = texelFetch(u_map, ivec2(gl_FragCoord.xy - u_region_origin), 0);
  if (ray.x < -1.0e8) {  // a black pixel of the display
    colour = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  const vec2 uv = surface_uv(ray.xy, ray.zw * u_parallax_gain);
  const bool outside = any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)));
  colour = vec4(u_cut_outside != 0 && outside ? vec3(0.0)
                                              : textureLod(u_view, uv * u_texture_scale + u_texture_offset, 0.0).rgb,
                1.0);
}
