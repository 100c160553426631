#version 450
#extension GL_GOOGLE_include_directive : require
// Counting sort, pass 3: particle ids into their cell's range of the sorted array.
#include "common/dispatch.glsl"
#include "common/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SORT_KEY) readonly buffer CellOf { uint cell_of[]; };
layout(std430, binding = TS_SORT_SLOT) readonly buffer Slot { uint slot[]; };
layout(std430, binding = TS_SORT_BUCKET_START) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = TS_SORT_SORTED) writeonly buffer Sorted { uint sorted_ids[]; };
#include "common/params.h"
layout(std140, binding = TS_GRID_PARAMS) uniform GridBlock { GridParams params; };
void main() {
  uint i = dispatch_item();
  if (i < params.sizes.x) sorted_ids[cell_start[cell_of[i]] + slot[i]] = i;
}
