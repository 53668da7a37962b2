#version 450 core
// Pass 2 of the defect compensation on GL (compositor/gl/gl_defect_compensation.cpp): one point
// per pixel that takes shares, at that pixel of the packed frame, carrying the sum of its shares:
// weight × the difference of each defect it takes a share of (pass 1's texture).

struct Share {
  int defect;  // the defect's slot in the differences texture
  float weight;
};
layout(std430, binding = 1) readonly buffer Pixels {
  ivec4 pixels[];  // xy: the pixel on its panel; z: its first share, w: how many
};
layout(std430, binding = 2) readonly buffer Shares { Share shares[]; };
layout(binding = 1) uniform sampler2D u_differences;
layout(location = 0) uniform ivec2 u_origin;  // the panel's top-left corner in the packed frame
layout(location = 1) uniform ivec2 u_slots;   // the differences texture's size
layout(location = 2) uniform ivec2 u_target;  // the packed frame's size

flat out vec4 v_value;

void main() {
  const ivec4 pixel = pixels[gl_VertexID];
  vec3 sum = vec3(0.0);
  for (int i = pixel.z; i < pixel.z + pixel.w; ++i) {
    const Share share = shares[i];
    const ivec2 slot = ivec2(share.defect % u_slots.x, share.defect / u_slots.x);
    sum += share.weight * texelFetch(u_differences, slot, 0).rgb;
  }
  v_value = vec4(sum, 0.0);
  gl_Position = vec4((vec2(u_origin + pixel.xy) + 0.5) / vec2(u_target) * 2.0 - 1.0, 0.0, 1.0);
}
