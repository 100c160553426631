#version 450
#extension GL_GOOGLE_include_directive : require
// Declares every shared layout in a std430 block so tests can read the compiler's offsets back.
#include "common/layouts.h"
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer SdfTriangles { SdfTriangle sdf_triangles[]; };
layout(std430, binding = 1) buffer SamplerGrids { SamplerGrid sampler_grids[]; };
layout(std430, binding = 2) buffer SimPairs { SimPair sim_pairs[]; };
layout(std430, binding = 3) buffer SimPlanes { SimPlane sim_planes[]; };
layout(std430, binding = 4) buffer SdfPrisms { SdfPrism sdf_prisms[]; };
layout(std430, binding = 5) buffer SimCylinders { SimCylinder sim_cylinders[]; };
layout(std430, binding = 6) buffer SimSprings { SimSpringSlots sim_springs[]; };
layout(std430, binding = 7) buffer SimSprings64 { SimSpringSlots64 sim_springs64[]; };
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
}
