#version 450
#extension GL_GOOGLE_include_directive : require
// Counting sort, pass 4: insertion sort of each cell's ids, so neighbours are always visited in index
// order and float sums over them are bitwise reproducible. Cells hold a handful of ids.
#include "common/dispatch.glsl"
#include "common/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SORT_BUCKET_COUNT) readonly buffer CellCount { uint cell_count[]; };
layout(std430, binding = TS_SORT_BUCKET_START) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = TS_SORT_SORTED) buffer Sorted { uint sorted_ids[]; };
#include "common/params.h"
layout(std140, binding = TS_GRID_PARAMS) uniform GridBlock { GridParams params; };
void main() {
  uint c = dispatch_item();
  if (c >= params.sizes.y) return;
  uint begin = cell_start[c], n = cell_count[c];
  for (uint a = 1u; a < n; ++a) {
    uint key = sorted_ids[begin + a];
    uint b = a;
    while (b > 0u && sorted_ids[begin + b - 1u] > key) {
      sorted_ids[begin + b] = sorted_ids[begin + b - 1u];
      --b;
    }
    sorted_ids[begin + b] = key;
  }
}
