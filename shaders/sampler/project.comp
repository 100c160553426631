#version 450
#extension GL_GOOGLE_include_directive : require
// Final projection onto the zero level set: p <- p - phi grad(phi), repeated by the host. Repulsion
// on a curved surface leaves particles a few percent of the spacing off it (formulas.md).
#include "sampler/sdf_sample.glsl"
layout(local_size_x = 128) in;
layout(std430, binding = 0) buffer Positions { vec4 positions[]; };
uniform uint count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec3 p = positions[i].xyz;
  vec4 s = sample_sdf(p);
  positions[i] = vec4(p - s.w * s.xyz, 0.0);
}
