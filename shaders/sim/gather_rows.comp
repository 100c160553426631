#version 450
#extension GL_GOOGLE_include_directive : require
// Re-sort, pass 4: dst row r = src row index[r], rows of `width` uvec4 words, copied bit for bit (so
// any per-body or per-particle array, float or double, moves with one kernel).
#include "common/dispatch.glsl"
#include "sim/bindings.h"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_GATHER_SOURCE) readonly buffer Src { uvec4 src[]; };
layout(std430, binding = TS_SIM_GATHER_DESTINATION) writeonly buffer Dst { uvec4 dst[]; };
layout(std430, binding = TS_SIM_GATHER_INDEX) readonly buffer Index { uint index[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform GatherBlock { SimGatherParams params; };
void main() {
  uint r = dispatch_item();
  if (r >= params.shape.x) return;
  uint from = index[r] * params.shape.y, to = r * params.shape.y;
  for (uint k = 0u; k < params.shape.y; ++k) dst[to + k] = src[from + k];
}
