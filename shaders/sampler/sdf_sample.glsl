// The SDF as the sampler reads it: the sparse NanoVDB level set (sdf::SparseField) with trilinear
// values and central-difference gradients (common/sparse_field.glsl). Particle positions are relative
// to the grid's voxel (0,0,0) centre, in metres, so float precision does not depend on where the mesh
// sits. The including kernel includes sampler/bindings.h first.
#ifndef TETRASAND_SAMPLER_SDF_SAMPLE_GLSL
#define TETRASAND_SAMPLER_SDF_SAMPLE_GLSL

layout(std430, binding = TS_SAMPLER_SPARSE_FIELD) readonly buffer SparseField { uint pnanovdb_buf_data[]; };
// The field's parameter block at this stage's slot.
#define TS_FIELD_PARAMS TS_SAMPLER_FIELD_PARAMS
// The field's root table (FieldRootTile[]) at this stage's slot.
#define TS_FIELD_ROOTS TS_SAMPLER_FIELD_ROOTS
// Chunks 1-7 of a field larger than one storage block, at this stage's slots.
#define TS_FIELD_CHUNK_1 TS_SAMPLER_FIELD_CHUNK_1
#define TS_FIELD_CHUNK_2 TS_SAMPLER_FIELD_CHUNK_2
#define TS_FIELD_CHUNK_3 TS_SAMPLER_FIELD_CHUNK_3
#define TS_FIELD_CHUNK_4 TS_SAMPLER_FIELD_CHUNK_4
#define TS_FIELD_CHUNK_5 TS_SAMPLER_FIELD_CHUNK_5
#define TS_FIELD_CHUNK_6 TS_SAMPLER_FIELD_CHUNK_6
#define TS_FIELD_CHUNK_7 TS_SAMPLER_FIELD_CHUNK_7
#include "common/sparse_field.glsl"

// xyz: unit gradient (zero where undefined, as off the band), w: signed distance [m].
vec4 sample_sdf(vec3 p) {
  FieldReader reader = field_reader();
  return field_sample(reader, p / field_params.scale.x);
}

#endif
