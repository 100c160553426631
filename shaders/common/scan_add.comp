#version 450
#extension GL_GOOGLE_include_directive : require
// Exclusive prefix sum, pass 2: adds each block's scanned offset to its 512 values.
#include "common/dispatch.glsl"
#include "common/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SCAN_VALUES) buffer Values { uint values[]; };
layout(std430, binding = TS_SCAN_BLOCK_SUMS) readonly buffer BlockOffsets { uint block_offsets[]; };
#include "common/params.h"
layout(std140, binding = TS_SCAN_PARAMS) uniform ScanBlock { ItemCount params; };
void main() {
  uint i = dispatch_item();
  if (i < params.count.x) values[i] += block_offsets[i / 512u];
}
