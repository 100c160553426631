#version 450
#extension GL_GOOGLE_include_directive : require
// Counting sort, pass 1: each particle finds its hashed cell and takes a slot in it. Slot order within
// a cell depends on atomics; grid_sort_cells.comp restores index order so results stay deterministic.
#include "common/dispatch.glsl"
#include "common/hash_grid.glsl"
#include "common/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_GRID_POSITIONS) readonly buffer Positions { vec4 positions[]; };
layout(std430, binding = TS_SORT_KEY) writeonly buffer CellOf { uint cell_of[]; };
layout(std430, binding = TS_SORT_BUCKET_COUNT) buffer CellCount { uint cell_count[]; };
layout(std430, binding = TS_SORT_SLOT) writeonly buffer Slot { uint slot[]; };
#include "common/params.h"
layout(std140, binding = TS_GRID_PARAMS) uniform GridBlock { GridParams params; };
void main() {
  uint i = dispatch_item();
  if (i >= params.sizes.x) return;
  uint h = hash_cell(cell_of_position(positions[i].xyz, params.cell.x), params.sizes.y);
  cell_of[i] = h;
  slot[i] = atomicAdd(cell_count[h], 1u);
}
