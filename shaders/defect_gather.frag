#version 450 core
// The defect's difference as it is, into a float texture (no clamping).
flat in vec4 v_value;
out vec4 colour;

void main() { colour = v_value; }
