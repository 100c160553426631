#version 450
#extension GL_GOOGLE_include_directive : require
// Re-sort, pass 1: each body's sort key, the Morton code of the cell its centre lies in (low 10 bits
// of each cell coordinate, interleaved) masked to the table size, so bodies in neighbouring cells get
// nearby keys and end up near each other in memory; and a slot in its key's bucket (order fixed later
// by common/grid_sort_cells.comp, so the result does not depend on the atomics).
#include "common/dispatch.glsl"
#include "common/bindings.h"
#include "sim/bindings.h"
#include "common/hash_grid.glsl"
#include "common/layouts.h"
#include "sim/precision.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SIM_BODY_POSITION) readonly buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SORT_KEY) writeonly buffer Key { uint key[]; };
layout(std430, binding = TS_SORT_BUCKET_COUNT) buffer Count { uint bucket_count[]; };
layout(std430, binding = TS_SORT_SLOT) writeonly buffer Slot { uint slot[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform KeysBlock { GridParams params; };

// Spreads the low 10 bits of v to every third bit.
uint spread_bits(uint v) {
  v &= 0x3ffu;
  v = (v | (v << 16u)) & 0x030000ffu;
  v = (v | (v << 8u)) & 0x0300f00fu;
  v = (v | (v << 4u)) & 0x030c30c3u;
  v = (v | (v << 2u)) & 0x09249249u;
  return v;
}

void main() {
  uint b = dispatch_item();
  if (b >= params.sizes.x) return;
  uvec3 c = uvec3(cell_of_position(vec3(body_position[b].xyz), params.cell.x));
  uint k = (spread_bits(c.x) | (spread_bits(c.y) << 1u) | (spread_bits(c.z) << 2u)) & (params.sizes.y - 1u);
  key[b] = k;
  slot[b] = atomicAdd(bucket_count[k], 1u);
}
