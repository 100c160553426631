#version 450
// One vertex per prism corner: an indexed GL_LINES_ADJACENCY draw with index 4*triangle + corner, so
// gl_VertexID carries both. The geometry shader reads the whole prism itself; this stage only forwards.
flat out uint v_triangle;
void main() {
  v_triangle = uint(gl_VertexID) >> 2;
  gl_Position = vec4(0.0);
}
