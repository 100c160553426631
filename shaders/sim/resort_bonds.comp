#version 450
#extension GL_GOOGLE_include_directive : require
// Re-sort, pass 6, per bond: its spheres named by their new GPU indices (the bond order, and so every
// per-particle sum of bond loads, is unchanged).
#include "common/dispatch.glsl"
#include "sim/bindings.h"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_BOND_PAIR) buffer Pairs { uvec4 bond_pair[]; };
layout(std430, binding = TS_SIM_RESORT_DESTINATION) readonly buffer Destination { uint new_of_old[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform BondsBlock { ItemCount params; };
void main() {
  uint k = dispatch_item();
  if (k >= params.count.x) return;
  bond_pair[k].xy = uvec2(new_of_old[bond_pair[k].x], new_of_old[bond_pair[k].y]);
}
