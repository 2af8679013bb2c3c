#version 450
// Full-screen triangle; v_t is 0 at the top of the screen and 1 at the bottom.
layout(location = 0) out float v_t;

void main() {
  vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
  v_t = p.y;
  gl_Position = vec4(p * 2.0 - 1.0, 1.0, 1.0);
}
