#version 450
#extension GL_GOOGLE_include_directive : require
// Leaf field, per slab, pass 2: each band leaf of the slab takes slot `used + offset`, `used` the slots
// of the slabs before and `offset` the exclusive scan of the flags (slab order: the same slots run
// after run, never an atomic's arrival order). The slab's last cell writes the new total into the
// other counter (LeafBuildParams.cells.w alternates), so no invocation reads a counter being written.
// A leaf past the slots the host allocated (its bound was wrong) reads as outside and raises the
// overflow counter, which the host checks once after the last slab.
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SDF_LEAF_INDEX) buffer LeafIndex { uint leaf_index[]; };
layout(std430, binding = TS_SDF_LEAF_FLAGS) readonly buffer LeafOffsets { uint leaf_offsets[]; };
layout(std430, binding = TS_SDF_LEAF_COUNTS) buffer LeafCounts { uint leaf_counts[4]; };
#include "common/params.h"
layout(std140, binding = TS_SDF_LEAF_PARAMS) uniform LeafBlock { LeafBuildParams params; };
void main() {
  uint c = dispatch_item();
  if (c >= params.cells.x) return;
  uint parity = params.cells.w & 1u;
  uint cell = params.cells.y + c;
  bool band = leaf_index[cell] == TS_LEAF_BAND;
  uint slot = leaf_counts[parity] + leaf_offsets[c];
  if (band) {
    if (slot < params.cells.z) {
      leaf_index[cell] = slot;
    } else {
      leaf_index[cell] = TS_LEAF_OUTSIDE;
      leaf_counts[3] = 1u;
    }
  }
  if (c + 1u == params.cells.x) leaf_counts[1u - parity] = slot + (band ? 1u : 0u);
}
