// The SDF as the sampler reads it: the sparse NanoVDB level set (sdf::SparseField) with trilinear
// values and central-difference gradients (common/sparse_field.glsl). Particle positions are relative
// to the grid's voxel (0,0,0) centre, in metres, so float precision does not depend on where the mesh
// sits. The including kernel includes sampler/bindings.h first.
#ifndef TETRASAND_SAMPLER_SDF_SAMPLE_GLSL
#define TETRASAND_SAMPLER_SDF_SAMPLE_GLSL

layout(std430, binding = TS_SAMPLER_SPARSE_FIELD) readonly buffer SparseField { uint pnanovdb_buf_data[]; };
#include "common/sparse_field.glsl"

// xyz: unit gradient (zero where undefined, as off the band), w: signed distance [m].
vec4 sample_sdf(vec3 p) {
  FieldReader reader = field_reader();
  return field_sample(reader, p / field_voxel_size);
}

#endif
