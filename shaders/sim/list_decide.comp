#version 450
#extension GL_GOOGLE_include_directive : require
// Contact candidate lists, the rebuild decision, one invocation a step after update_particles.comp:
// rebuild when forced (after an upload, a restore or a re-sort) or when some particle has moved more
// than half the skin since the last build (sim::lists_need_rebuild; a NaN displacement rebuilds too).
// It copies the rebuild passes' group counts (the plan, recorded by gpu::Queue at upload) into the
// indirect dispatch arguments, or zeros, so the host never reads the decision back.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
layout(local_size_x = 1) in;
layout(std430, binding = TS_SIM_LIST_STATE) buffer S { uint list_state[]; };
layout(std430, binding = TS_SIM_LIST_PLAN) readonly buffer Plan { uvec4 plan[]; };
layout(std430, binding = TS_SIM_LIST_ARGS) writeonly buffer Args { uvec4 args[]; };
layout(std430, binding = TS_SIM_COUNTERS) buffer C { uint counters[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform ListBlock { SimListParams params; };
void main() {
  if (dispatch_item() != 0u) return;
  float moved = uintBitsToFloat(list_state[TS_SIM_LIST_MAX_DISPLACEMENT]);
  bool rebuild = list_state[TS_SIM_LIST_FORCED] != 0u || !(2.0 * moved <= params.lengths.y);
  for (uint r = 0u; r < params.sizes.w; ++r) args[r] = rebuild ? plan[r] : uvec4(0u);
  if (rebuild) counters[TS_SIM_COUNTER_LIST_BUILDS] += 1u;
  // update_particles.comp takes the next step's maximum from zero.
  list_state[TS_SIM_LIST_MAX_DISPLACEMENT] = 0u;
  list_state[TS_SIM_LIST_FORCED] = 0u;
}
