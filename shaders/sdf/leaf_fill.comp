#version 450
#extension GL_GOOGLE_include_directive : require
// Leaf field, per slab, pass 3: one invocation per band leaf of the slab copies its band voxels out of
// the slab target (distance [voxels] times the voxel size, the float product the host's level set
// stores) and gives every other voxel of the leaf +-background by OpenVDB's signed flood fill of a
// leaf (tools::SignedFloodFill): the sign of the last band voxel met along the fastest axis, the row
// start's along the middle one, the plane start's along the slowest, the leaf's first band voxel's
// before any. For a distance field that is the true sign: voxels off the band have |d| >= band and d
// is 1-Lipschitz, so the sign cannot change along a path of them, nor between one and a band neighbour.
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
layout(local_size_x = 64) in;
layout(binding = TS_SDF_UNIT_SLAB) uniform sampler2DArray slab;
layout(std430, binding = TS_SDF_LEAF_INDEX) readonly buffer LeafIndex { uint leaf_index[]; };
layout(std430, binding = TS_SDF_LEAF_VALUES) buffer LeafValues { float leaf_values[]; };
#include "common/params.h"
layout(std140, binding = TS_SDF_LEAF_PARAMS) uniform LeafBlock { LeafBuildParams params; };
#include "sdf/leaf_cell.glsl"

uint band_mask[16];  // bit v: voxel v of the leaf is a band voxel

bool in_band(uint v) { return (band_mask[v >> 5u] & (1u << (v & 31u))) != 0u; }

void main() {
  uint c = dispatch_item();
  if (c >= params.cells.x) return;
  uint slot = leaf_index[params.cells.y + c];
  if (slot >= TS_LEAF_EMPTY) return;
  uint base = slot * 512u;
  ivec3 cell = slab_leaf_cell(c);
  uint first = 512u;
  for (uint word = 0u; word < 16u; ++word) band_mask[word] = 0u;
  for (uint v = 0u; v < 512u; ++v) {
    bool in_grid;
    ivec3 texel = leaf_voxel_texel(cell, v, in_grid);
    float d = in_grid ? texelFetch(slab, texel, 0).w : 1e30;
    if (!(abs(d) < params.band.x)) continue;
    leaf_values[base + v] = d * params.band.y;
    band_mask[v >> 5u] |= 1u << (v & 31u);
    first = min(first, v);
  }
  float background = params.band.z;
  bool inside_z = leaf_values[base + first] < 0.0;  // a band leaf has a band voxel: first < 512
  for (uint z = 0u; z < 8u; ++z) {
    uint z00 = z << 6u;
    if (in_band(z00)) inside_z = leaf_values[base + z00] < 0.0;
    bool inside_y = inside_z;
    for (uint y = 0u; y < 8u; ++y) {
      uint zy0 = z00 + (y << 3u);
      if (in_band(zy0)) inside_y = leaf_values[base + zy0] < 0.0;
      bool inside_x = inside_y;
      for (uint x = 0u; x < 8u; ++x) {
        uint v = zy0 + x;
        if (in_band(v)) {
          inside_x = leaf_values[base + v] < 0.0;
        } else {
          leaf_values[base + v] = inside_x ? -background : background;
        }
      }
    }
  }
}
