#version 450
#extension GL_GOOGLE_include_directive : require
// Re-sort, pass 3, per new body: its new range (keyframe references kept), and for each of its
// particles where it comes from, where it goes, and which body now owns it.
#include "common/dispatch.glsl"
#include "common/bindings.h"
#include "sim/bindings.h"
#include "common/layouts.h"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_RESORT_ORDER) readonly buffer Order { uint order[]; };
layout(std430, binding = TS_SIM_RESORT_NEW_FIRST) readonly buffer NewFirst { uint new_first[]; };
layout(std430, binding = TS_SIM_BODY_RANGE) readonly buffer BR { uvec4 body_range[]; };
layout(std430, binding = TS_SIM_RESORT_NEW_RANGE) writeonly buffer NewRange { uvec4 new_range[]; };
layout(std430, binding = TS_SIM_RESORT_SOURCE) writeonly buffer Source { uint source_particle[]; };  // new particle -> old
layout(std430, binding = TS_SIM_RESORT_DESTINATION) writeonly buffer Destination { uint new_of_old[]; };  // old particle -> new
layout(std430, binding = TS_SIM_RESORT_OWNER) writeonly buffer Owner { uint owner[]; };             // new particle -> new body
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform ParticlesBlock { ItemCount params; };
void main() {
  uint b = dispatch_item();
  if (b >= params.count.x) return;
  uvec4 old_range = body_range[order[b]];
  uint first = new_first[b];
  new_range[b] = uvec4(first, old_range.y, old_range.z, old_range.w);
  for (uint k = 0u; k < old_range.y; ++k) {
    source_particle[first + k] = old_range.x + k;
    new_of_old[old_range.x + k] = first + k;
    owner[first + k] = b;
  }
}
