#version 450
#extension GL_GOOGLE_include_directive : require
// Leaf field, per slab, pass 1 (sdf/leaf_field.h): one invocation per 8^3 leaf cell of the finished
// slab. A cell holding a band voxel (|d| < band) is a band leaf: flag 1 (scanned next into its slot)
// and TS_LEAF_BAND in the grid's leaf index; any other cell is TS_LEAF_EMPTY until leaf_signs.comp
// gives it its sign. The band voxels are counted (an integer sum: the same whatever the order).
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
layout(local_size_x = 64) in;
layout(binding = TS_SDF_UNIT_SLAB) uniform sampler2DArray slab;  // xyz unit gradient, w distance [voxels]
layout(std430, binding = TS_SDF_LEAF_INDEX) writeonly buffer LeafIndex { uint leaf_index[]; };
layout(std430, binding = TS_SDF_LEAF_FLAGS) writeonly buffer LeafFlags { uint leaf_flags[]; };
layout(std430, binding = TS_SDF_LEAF_COUNTS) buffer LeafCounts { uint leaf_counts[4]; };
#include "common/params.h"
layout(std140, binding = TS_SDF_LEAF_PARAMS) uniform LeafBlock { LeafBuildParams params; };
#include "sdf/leaf_cell.glsl"
void main() {
  uint c = dispatch_item();
  if (c >= params.cells.x) return;
  ivec3 cell = slab_leaf_cell(c);
  uint band_voxels = 0u;
  for (uint v = 0u; v < 512u; ++v) {
    bool in_grid;
    ivec3 texel = leaf_voxel_texel(cell, v, in_grid);
    if (in_grid && abs(texelFetch(slab, texel, 0).w) < params.band.x) ++band_voxels;
  }
  leaf_flags[c] = band_voxels > 0u ? 1u : 0u;
  leaf_index[params.cells.y + c] = band_voxels > 0u ? TS_LEAF_BAND : TS_LEAF_EMPTY;
  if (band_voxels > 0u) atomicAdd(leaf_counts[2], band_voxels);
}
