#version 450 core
// One triangle covering the whole viewport, positions from gl_VertexID (no vertex buffer).
void main() {
  const vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
