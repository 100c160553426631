#version 450
#extension GL_GOOGLE_include_directive : require
// Re-sort, pass 2: the particle count of each body in its new place, to be scanned into the bodies'
// new first particles (a body's particles stay contiguous and in their order).
#include "common/dispatch.glsl"
#include "common/bindings.h"
#include "sim/bindings.h"
#include "common/layouts.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SIM_RESORT_ORDER) readonly buffer Order { uint order[]; };  // new body -> old body
layout(std430, binding = TS_SIM_BODY_RANGE) readonly buffer BR { uvec4 body_range[]; };
layout(std430, binding = TS_SIM_RESORT_NEW_FIRST) writeonly buffer NewFirst { uint new_first[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform RangesBlock { ItemCount params; };
void main() {
  uint b = dispatch_item();
  if (b < params.count.x) new_first[b] = body_range[order[b]].y;
}
