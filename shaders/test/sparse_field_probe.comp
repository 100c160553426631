#version 450
#extension GL_GOOGLE_include_directive : require
// Reads an sdf::SparseField at given grid-local positions the way the sampler and the preview do,
// so tests can compare with the host's NanoVDB/OpenVDB values. mode 0: x = the voxel value at
// round(position); mode 1: x = trilinear value; mode 2: xyz = field_sample's unit gradient, w = its value.
#include "test/bindings.h"
layout(local_size_x = 64) in;
layout(std430, binding = TS_TEST_FIELD_GRID) readonly buffer SparseField { uint pnanovdb_buf_data[]; };
#include "common/sparse_field.glsl"
layout(std430, binding = TS_TEST_FIELD_POINTS) readonly buffer Points { vec4 points[]; };
layout(std430, binding = TS_TEST_FIELD_VALUES) writeonly buffer Values { vec4 values[]; };
uniform uint count;
uniform int mode;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  FieldReader reader = field_reader();
  vec3 x = points[i].xyz;
  if (mode == 0) {
    values[i] = vec4(field_voxel(reader, ivec3(round(x))), 0.0, 0.0, 0.0);
  } else if (mode == 1) {
    values[i] = vec4(field_trilinear(reader, x), 0.0, 0.0, 0.0);
  } else {
    values[i] = field_sample(reader, x);
  }
}
