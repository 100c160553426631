// The SDF as the preview reads it: the sparse NanoVDB level set (sdf::SparseField) through
// common/sparse_field.glsl, trilinear between voxel centres, in voxel units and clamped to the band.
// Voxel centres sit at integer voxel coordinates of the grid spec (the box of the band).
#ifndef TETRASAND_PREVIEW_VOLUME_GLSL
#define TETRASAND_PREVIEW_VOLUME_GLSL

#include "preview/bindings.h"

layout(std430, binding = TS_PREVIEW_SPARSE_FIELD) readonly buffer SparseField { uint pnanovdb_buf_data[]; };
// The field's parameter block at this stage's slot.
#define TS_FIELD_PARAMS TS_PREVIEW_FIELD_PARAMS
// The field's root table (FieldRootTile[]) at this stage's slot.
#define TS_FIELD_ROOTS TS_PREVIEW_FIELD_ROOTS
// Chunks 1-7 of a field larger than one storage block, at this stage's slots.
#define TS_FIELD_CHUNK_1 TS_PREVIEW_FIELD_CHUNK_1
#define TS_FIELD_CHUNK_2 TS_PREVIEW_FIELD_CHUNK_2
#define TS_FIELD_CHUNK_3 TS_PREVIEW_FIELD_CHUNK_3
#define TS_FIELD_CHUNK_4 TS_PREVIEW_FIELD_CHUNK_4
#define TS_FIELD_CHUNK_5 TS_PREVIEW_FIELD_CHUNK_5
#define TS_FIELD_CHUNK_6 TS_PREVIEW_FIELD_CHUNK_6
#define TS_FIELD_CHUNK_7 TS_PREVIEW_FIELD_CHUNK_7
#include "common/sparse_field.glsl"

#include "common/params.h"
layout(std140, binding = TS_PREVIEW_VOLUME) uniform VolumeBlock { VolumeParams volume; };

// One accessor per invocation, made on first use: it caches the last node, so the neighbouring
// reads of a march skip most of the tree walk.
FieldReader volume_reader;
bool volume_reader_ready = false;

void ensure_volume_reader() {
  if (volume_reader_ready) return;
  volume_reader = field_reader();
  volume_reader_ready = true;
}

vec3 to_voxel(vec3 p) { return (p - volume.origin_voxel.xyz) / volume.origin_voxel.w; }

// Signed distance [voxels] at voxel coordinates u.
float sdf_at(vec3 u) {
  ensure_volume_reader();
  return clamp(field_trilinear(volume_reader, u) / volume.origin_voxel.w, -volume.dims_band.w, volume.dims_band.w);
}

// Unit outward normal: central differences one voxel apart, so the normal varies smoothly across
// voxel faces (the trilinear interpolant's own gradient jumps there and would show as banding).
vec3 sdf_normal(vec3 u) {
  vec3 g = vec3(sdf_at(u + vec3(1, 0, 0)) - sdf_at(u - vec3(1, 0, 0)),
                sdf_at(u + vec3(0, 1, 0)) - sdf_at(u - vec3(0, 1, 0)),
                sdf_at(u + vec3(0, 0, 1)) - sdf_at(u - vec3(0, 0, 1)));
  float len = length(g);
  return len > 1e-12 ? g / len : vec3(0.0, 0.0, 1.0);
}

#endif
