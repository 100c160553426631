#version 450
#extension GL_GOOGLE_include_directive : require
// Re-sort, pass 5, per new particle: its owner is the body's new index, and its springs name their
// partner particles by their new ids (walls and free slots unchanged).
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "common/layouts.h"
#include "sim/precision.glsl"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_PARTICLE_INFO) buffer I { uvec4 particle_info[]; };
layout(std430, binding = TS_SIM_RESORT_DESTINATION) readonly buffer Destination { uint new_of_old[]; };
layout(std430, binding = TS_SIM_RESORT_OWNER) readonly buffer Owner { uint owner[]; };
#ifdef TS_FP64
layout(std430, binding = TS_SIM_SPRINGS) buffer Springs { SimSpringSlots64 springs[]; };
#else
layout(std430, binding = TS_SIM_SPRINGS) buffer Springs { SimSpringSlots springs[]; };
#endif
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform FixupBlock { SimFixupParams params; };
void main() {
  uint i = dispatch_item();
  if (i >= params.sizes.x) return;
  particle_info[i].x = owner[i];
  if (params.models.x == 0) return;
  for (uint s = 0u; s < TS_SIM_SPRING_SLOTS; ++s) {
    int partner = springs[i].partner[s / 4u][s % 4u];
    if (partner >= 0 && partner != TS_SIM_NO_PARTNER) springs[i].partner[s / 4u][s % 4u] = int(new_of_old[partner]);
  }
}
