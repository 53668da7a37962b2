#version 450 core
// One signed part of a pixel's sum of shares: a unorm framebuffer takes colours in 0..1, so the
// positive part is added (GL_FUNC_ADD) and the negative part subtracted (GL_FUNC_REVERSE_SUBTRACT)
// in two draws; per channel only one is not zero, so the pixel is clipped once. Alpha stays.
flat in vec4 v_value;
layout(location = 3) uniform float u_sign;  // +1: the positive part; −1: the negative part
out vec4 colour;

void main() { colour = vec4(max(v_value.rgb * u_sign, vec3(0.0)), 0.0); }
