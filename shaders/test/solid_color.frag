#version 450
// One colour on every fragment: the smallest fragment stage, used by tests of the GPU layer's draws.
uniform vec4 color;

layout(location = 0) out vec4 fragment;

void main() { fragment = color; }
