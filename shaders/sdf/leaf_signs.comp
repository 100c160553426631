#version 450
#extension GL_GOOGLE_include_directive : require
// Leaf field, after the last slab: one invocation per column of leaf cells (along z) gives each cell
// without band voxels the sign of the band leaf before it in the column, read at that leaf's +z face
// (voxel (0,0,7)). A column starts outside: the grid holds the mesh with a margin, so its first layer
// lies outside or in the band. The sign is the true one for the reason leaf_fill.comp gives: the
// cells between hold no band voxel, and the face voxel's neighbour across the face is one of them.
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
layout(local_size_x = 64) in;
layout(std430, binding = TS_SDF_LEAF_INDEX) buffer LeafIndex { uint leaf_index[]; };
layout(std430, binding = TS_SDF_LEAF_VALUES) readonly buffer LeafValues { float leaf_values[]; };
#include "common/params.h"
layout(std140, binding = TS_SDF_LEAF_PARAMS) uniform LeafBlock { LeafBuildParams params; };
void main() {
  uint column = dispatch_item();
  uint per_row = uint(params.leaves.x * params.leaves.y);
  if (column >= per_row) return;
  bool inside = false;
  for (uint z = 0u; z < uint(params.leaves.z); ++z) {
    uint cell = column + z * per_row;
    uint entry = leaf_index[cell];
    if (entry < TS_LEAF_EMPTY) {
      inside = leaf_values[entry * 512u + (7u << 6u)] < 0.0;
    } else if (entry == TS_LEAF_EMPTY) {
      leaf_index[cell] = inside ? TS_LEAF_INSIDE : TS_LEAF_OUTSIDE;
    }
  }
}
