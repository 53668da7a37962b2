#version 450 core
// Footprint prefilter, step 1 (DESIGN.md §4): the exact mean of each R_x × R_y block of view texels
// (R ∈ {1, 2, 4}), using bilinear taps placed on texel corners so one tap averages up to 2 × 2
// texels. Reads every view texel once; the result is a small texture the box pass works on.

layout(binding = 0) uniform sampler2D u_view;
layout(location = 0) uniform ivec2 u_block;  // R per axis

out vec4 colour;

void main() {
  const vec2 view_size = vec2(textureSize(u_view, 0));
  const vec2 base = floor(gl_FragCoord.xy) * vec2(u_block);
  const ivec2 taps = max(u_block / 2, ivec2(1));
  vec4 sum = vec4(0.0);
  for (int y = 0; y < taps.y; ++y) {
    for (int x = 0; x < taps.x; ++x) {
      // R = 1: the texel centre; R >= 2: the corner shared by a 2 × 2 group (weights ¼ each).
      const vec2 offset = mix(vec2(0.5), vec2(2 * x + 1, 2 * y + 1), greaterThan(u_block, ivec2(1)));
      sum += textureLod(u_view, (base + offset) / view_size, 0.0);
    }
  }
  colour = sum / float(taps.x * taps.y);
}
