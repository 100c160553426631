#version 450
#extension GL_GOOGLE_include_directive : require
// Contact statistics per work group (the host adds partials in order): x pair contacts, y wall
// contacts, z largest overlap ratio (max), w overlap clamps.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "common/layouts.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SIM_PARTICLE_STATS) readonly buffer S { vec4 particle_stats[]; };
layout(std430, binding = TS_SIM_STAT_PARTIALS) writeonly buffer Partials { vec4 partials[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform StatsBlock { ItemCount params; };
shared vec4 scratch[256];
void main() {
  uint i = dispatch_item(), t = gl_LocalInvocationID.x;
  if (dispatch_group() * gl_WorkGroupSize.x >= params.count.x) return;  // past the end: no partial
  scratch[t] = i < params.count.x ? particle_stats[i] : vec4(0.0);
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    barrier();
    if (t < stride) {
      vec4 a = scratch[t], b = scratch[t + stride];
      scratch[t] = vec4(a.x + b.x, a.y + b.y, max(a.z, b.z), a.w + b.w);
    }
  }
  if (t == 0u) partials[dispatch_group()] = scratch[0];
}
