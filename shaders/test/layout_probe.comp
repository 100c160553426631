#version 450
#extension GL_GOOGLE_include_directive : require
// Declares every shared layout in a std430 block so tests can read the compiler's offsets back.
#include "common/layouts.h"
#include "test/bindings.h"
layout(local_size_x = 1) in;
layout(std430, binding = TS_TEST_PROBE_SDF_TRIANGLES) buffer SdfTriangles { SdfTriangle sdf_triangles[]; };
layout(std430, binding = TS_TEST_PROBE_SAMPLER_GRIDS) buffer SamplerGrids { SamplerGrid sampler_grids[]; };
layout(std430, binding = TS_TEST_PROBE_SIM_PAIRS) buffer SimPairs { SimPair sim_pairs[]; };
layout(std430, binding = TS_TEST_PROBE_SIM_PLANES) buffer SimPlanes { SimPlane sim_planes[]; };
layout(std430, binding = TS_TEST_PROBE_SDF_PRISMS) buffer SdfPrisms { SdfPrism sdf_prisms[]; };
layout(std430, binding = TS_TEST_PROBE_SIM_CYLINDERS) buffer SimCylinders { SimCylinder sim_cylinders[]; };
layout(std430, binding = TS_TEST_PROBE_SIM_SPRINGS) buffer SimSprings { SimSpringSlots sim_springs[]; };
layout(std430, binding = TS_TEST_PROBE_SIM_SPRINGS64) buffer SimSprings64 { SimSpringSlots64 sim_springs64[]; };
layout(std430, binding = TS_TEST_PROBE_CERT_TRIANGLES) buffer CertTriangles { CertTriangle cert_triangles[]; };
layout(std430, binding = TS_TEST_PROBE_CERT_LEAVES) buffer CertLeaves { CertLeaf cert_leaves[]; };
layout(std430, binding = TS_TEST_PROBE_FIELD_ROOTS) buffer FieldRoots { FieldRootTile field_roots[]; };
void main() {
  // Touch each block so no compiler drops it.
  sdf_triangles[0].face_normal.w += 1.0;
  sampler_grids[0].dims.w += 1u;
  sim_pairs[0].extra.w += 1.0;
  sim_planes[0].extent.w += 1.0;
  sdf_prisms[0].normal_margin.w += 1.0;
  sim_cylinders[0].material.x += 1u;
  sim_springs[0].displacement[0].w += 1.0;
  sim_springs64[0].displacement[0].w += 1.0;
  cert_triangles[0].edge2.w += 1.0;
  cert_leaves[0].bounds.w += 1.0;
  field_roots[0].address.w += 1u;
}
