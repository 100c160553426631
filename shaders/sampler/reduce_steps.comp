#version 450
#extension GL_GOOGLE_include_directive : require
// Convergence reduction: per work group, the sum of the gradient steps of the mobile particles, the
// largest |phi|, the count of particles outside the band and the count of mobile particles. The host
// adds the partials in order (deterministic, no float atomics).
#include "common/dispatch.glsl"
#include "sampler/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SAMPLER_STEP_INFO) readonly buffer StepInfo { vec4 step_info[]; };
layout(std430, binding = TS_SAMPLER_PARTIALS) writeonly buffer Partials { vec4 partials[]; };
#include "common/params.h"
layout(std140, binding = TS_SAMPLER_PARAMS) uniform ReduceBlock { ItemCount params; };
shared vec4 scratch[256];
void main() {
  uint i = dispatch_item(), t = gl_LocalInvocationID.x;
  if (dispatch_group() * gl_WorkGroupSize.x >= params.count.x) return;  // past the end: no partial
  scratch[t] = i < params.count.x ? step_info[i] : vec4(0.0);
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    barrier();
    if (t < stride) {
      vec4 a = scratch[t], b = scratch[t + stride];
      scratch[t] = vec4(a.x + b.x, max(a.y, b.y), a.z + b.z, a.w + b.w);
    }
  }
  if (t == 0u) partials[dispatch_group()] = scratch[0];
}
