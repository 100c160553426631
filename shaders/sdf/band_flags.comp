#version 450
#extension GL_GOOGLE_include_directive : require
// Band compaction, pass 1: one flag per voxel of the finished slab, 1 where |d| < band (the voxels
// that go into the level set). An exclusive scan of the flags (common/scan_*.comp) then gives each
// band voxel its place in the compacted arrays, so only the band is read back.
#include "common/dispatch.glsl"
#include "sdf/bindings.h"
layout(local_size_x = 256) in;
layout(binding = TS_SDF_UNIT_SLAB) uniform sampler2DArray slab;  // xyz unit gradient, w distance [voxels]
layout(std430, binding = TS_SDF_BAND_FLAGS) writeonly buffer Flags { uint flags[]; };
#include "common/params.h"
layout(std140, binding = TS_SDF_BAND_PARAMS) uniform BandBlock { BandParams params; };
void main() {
  uint v = dispatch_item();
  if (v >= params.voxels.x) return;
  uint per_layer = uint(params.layer_size.x * params.layer_size.y);
  ivec3 texel = ivec3(int(v % uint(params.layer_size.x)), int((v % per_layer) / uint(params.layer_size.x)), int(v / per_layer));
  flags[v] = abs(texelFetch(slab, texel, 0).w) < params.band.x ? 1u : 0u;
}
