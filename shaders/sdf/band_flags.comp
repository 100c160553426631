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
uniform ivec2 layer_size;  // voxels along x, y
uniform uint voxels;       // layer_size.x * layer_size.y * layers
uniform float band;        // half-width [voxels]
void main() {
  uint v = dispatch_item();
  if (v >= voxels) return;
  uint per_layer = uint(layer_size.x * layer_size.y);
  ivec3 texel = ivec3(int(v % uint(layer_size.x)), int((v % per_layer) / uint(layer_size.x)), int(v / per_layer));
  flags[v] = abs(texelFetch(slab, texel, 0).w) < band ? 1u : 0u;
}
