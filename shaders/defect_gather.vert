#version 450 core
// Pass 1 of the defect compensation on GL (compositor/gl/gl_defect_compensation.cpp): one point
// per defect, at its slot of the differences texture, carrying what the defect was sent (read off
// the frame as drawn) minus what it shows.

struct Defect {
  ivec4 pixel;  // xy: the defect's pixel on its panel
  vec4 shown;   // rgb: what it shows whatever it is sent (0..1)
};
layout(std430, binding = 0) readonly buffer Defects { Defect defects[]; };
layout(binding = 0) uniform sampler2D u_frame;  // the packed frame
layout(location = 0) uniform ivec2 u_origin;    // the panel's top-left corner in the packed frame
layout(location = 1) uniform ivec2 u_slots;     // the differences texture's size

flat out vec4 v_value;

void main() {
  const Defect defect = defects[gl_VertexID];
  const vec4 sent = texelFetch(u_frame, u_origin + defect.pixel.xy, 0);
  v_value = vec4(sent.rgb - defect.shown.rgb, 0.0);
  const ivec2 slot = ivec2(gl_VertexID % u_slots.x, gl_VertexID / u_slots.x);
  gl_Position = vec4((vec2(slot) + 0.5) / vec2(u_slots) * 2.0 - 1.0, 0.0, 1.0);
}
