#version 450 core
// Pass 1 of the elemental images from a coordinate map (elemental.frag built with
// NELF_COORDINATE_MAP, rendered once per eye and view geometry): one fetch of the pixel's u_view
// coordinate, one bilinear tap. Black where the map says -1: the prefiltered view's clamped edge.

layout(binding = 0) uniform sampler2D u_view;  // the footprint-prefiltered view (black margin)
layout(binding = 1) uniform sampler2D u_map;   // RG32F, panel-sized: u_view coordinate per pixel
layout(location = 0) uniform vec2 u_region_origin;  // lower-left corner of the eye's region in the target (pixels)

out vec4 colour;

void main() {
  const vec2 coordinate = texelFetch(u_map, ivec2(gl_FragCoord.xy - u_region_origin), 0).xy;
  colour = vec4(textureLod(u_view, coordinate, 0.0).rgb, 1.0);
}
