#version 450
#extension GL_GOOGLE_include_directive : require
// Final projection onto the zero level set: p <- p - phi grad(phi), repeated by the host. Repulsion
// on a curved surface leaves particles a few percent of the spacing off it (formulas.md). Mobile
// particles only (positions.w = 1).
#include "common/dispatch.glsl"
#include "sampler/bindings.h"
#include "sampler/sdf_sample.glsl"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SAMPLER_POSITIONS) buffer Positions { vec4 positions[]; };
#include "common/params.h"
layout(std140, binding = TS_SAMPLER_PARAMS) uniform ProjectBlock { ItemCount params; };
void main() {
  uint i = dispatch_item();
  if (i >= params.count.x) return;
  vec4 pw = positions[i];
  if (pw.w == 0.0) return;  // frozen: already on the exact surface
  vec4 s = sample_sdf(pw.xyz);
  positions[i] = vec4(pw.xyz - s.w * s.xyz, pw.w);
}
