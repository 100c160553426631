#version 450
#extension GL_GOOGLE_include_directive : require
// Band compaction, pass 2: each band voxel writes its slab index and value at the place the scan of
// the flags gave it, in slab order (x fastest, then y, then layer), so the compacted band is in the
// same order as a scan of the whole slab on the host would find it.
#include "common/dispatch.glsl"
#include "sdf/bindings.h"
layout(local_size_x = 256) in;
layout(binding = TS_SDF_UNIT_SLAB) uniform sampler2DArray slab;
layout(std430, binding = TS_SDF_BAND_OFFSETS) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = TS_SDF_BAND_INDICES) writeonly buffer Indices { uint band_indices[]; };
layout(std430, binding = TS_SDF_BAND_VALUES) writeonly buffer Values { vec4 band_values[]; };
#include "common/params.h"
layout(std140, binding = TS_SDF_BAND_PARAMS) uniform BandBlock { BandParams params; };
void main() {
  uint v = dispatch_item();
  if (v >= params.voxels.x) return;
  uint per_layer = uint(params.layer_size.x * params.layer_size.y);
  ivec3 texel = ivec3(int(v % uint(params.layer_size.x)), int((v % per_layer) / uint(params.layer_size.x)), int(v / per_layer));
  vec4 value = texelFetch(slab, texel, 0);
  if (!(abs(value.w) < params.band.x)) return;
  band_indices[offsets[v]] = v;
  band_values[offsets[v]] = value;
}
