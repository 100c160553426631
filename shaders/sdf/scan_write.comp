#version 450
#extension GL_GOOGLE_include_directive : require
// Compute scan conversion, pass 3: one invocation per slab voxel. A voxel that scan_pairs.comp gave a
// nearest triangle takes that triangle's value (sdf/voxel_value.glsl, the fragment shader's), stored
// into the same slab target the geometry path draws into; the others keep the target's clear value.
// From here on both paths share the band compaction (band_flags.comp, band_scatter.comp).
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SDF_TRIANGLES) readonly buffer Triangles { SdfTriangle triangles[]; };
layout(std430, binding = TS_SDF_NEAREST_TRIANGLE) readonly buffer NearestTriangle { uint nearest_triangle[]; };
layout(binding = TS_SDF_IMAGE_SLAB, rgba32f) writeonly uniform image2DArray slab;
#include "common/params.h"
#include "sdf/voxel_value.glsl"
layout(std140, binding = TS_SDF_COMPUTE_PARAMS) uniform ComputeScanBlock { ComputeScanParams params; };

void main() {
  uint v = dispatch_item();
  if (v >= params.pairs.z) return;
  uint nearest = nearest_triangle[v];
  if (nearest == 0u) return;
  uint per_layer = uint(params.grid.x * params.grid.y);
  ivec3 texel = ivec3(int(v % uint(params.grid.x)), int((v % per_layer) / uint(params.grid.x)), int(v / per_layer));
  vec3 p = vec3(texel.xy, float(params.slab.x + texel.z));
  imageStore(slab, texel, voxel_value(p, triangles[~nearest]));
}
