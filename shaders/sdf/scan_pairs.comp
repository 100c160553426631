#version 450
#extension GL_GOOGLE_include_directive : require
// Compute scan conversion, passes 1 and 2: one work group per triangle/brick pair, one invocation per
// voxel of the brick (sdf/compute_scan.h). Pass 1 keeps, per slab voxel, the least distance to any
// triangle within the band (an atomic minimum on the distance's bits: non-negative floats order as
// their bits do). Pass 2 (NEAREST_TRIANGLE) recomputes the same distance and, where it equals that
// minimum, keeps the least triangle index: ties go to the lowest index whatever order the groups run
// in, so the field is the same bytes run after run. Both store complements (atomicMax of ~x is the
// minimum of x), so a buffer cleared to zero reads "no triangle yet".
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
#ifndef BRICK
#define BRICK 4
#endif
layout(local_size_x = BRICK, local_size_y = BRICK, local_size_z = BRICK) in;
layout(std430, binding = TS_SDF_TRIANGLES) readonly buffer Triangles { SdfTriangle triangles[]; };
layout(std430, binding = TS_SDF_PAIRS) readonly buffer Pairs { uvec2 pairs[]; };
layout(std430, binding = TS_SDF_PAIR_ROWS) readonly buffer PairRows { uint pair_rows[]; };
#ifdef NEAREST_TRIANGLE
layout(std430, binding = TS_SDF_NEAREST_DISTANCE) readonly buffer NearestDistance { uint nearest_distance[]; };
layout(std430, binding = TS_SDF_NEAREST_TRIANGLE) coherent buffer NearestTriangle { uint nearest_triangle[]; };
#else
layout(std430, binding = TS_SDF_NEAREST_DISTANCE) coherent buffer NearestDistance { uint nearest_distance[]; };
#endif
#include "common/params.h"
#include "sdf/voxel_value.glsl"
layout(std140, binding = TS_SDF_COMPUTE_PARAMS) uniform ComputeScanBlock { ComputeScanParams params; };

// The brick row (brick z) of pair `pair`: the last row whose first pair is at or before it.
int brick_row(uint pair) {
  int lo = 0, hi = params.grid.w;  // pair_rows[lo] <= pair < pair_rows[hi]
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (pair_rows[mid] <= pair) lo = mid; else hi = mid;
  }
  return lo;
}

void main() {
  uint group = dispatch_group();
  if (group >= params.pairs.y) return;
  uint pair = params.pairs.x + group;
  uvec2 record = pairs[pair];
  ivec3 brick = ivec3(int(record.y & 0xFFFFu), int(record.y >> 16), brick_row(pair));
  ivec3 voxel = brick * BRICK + ivec3(gl_LocalInvocationID);
  int layer = voxel.z - params.slab.x;
  if (any(greaterThanEqual(voxel, params.grid.xyz)) || layer < 0 || layer >= params.slab.y) return;
  SdfTriangle t = triangles[record.x];
  vec3 p = vec3(voxel);
  // Cheap rejections before the exact distance, which no voxel they drop can be within the band of:
  // outside the triangle's box grown by the band, or farther than the band from its plane. The slack
  // (a hundredth of a voxel) keeps float rounding of these bounds, ~1e-7 of the grid coordinate, from
  // dropping a voxel whose exact distance is just inside.
  float reach = params.band.x + 0.01;
  vec3 lo = min(min(t.vertex[0].xyz, t.vertex[1].xyz), t.vertex[2].xyz) - reach;
  vec3 hi = max(max(t.vertex[0].xyz, t.vertex[1].xyz), t.vertex[2].xyz) + reach;
  float plane = abs(dot(p - t.vertex[0].xyz, t.face_normal.xyz));
  if (any(lessThan(p, lo)) || any(greaterThan(p, hi)) || plane > reach) return;
  uint slot = uint(voxel.x) + uint(params.grid.x) * (uint(voxel.y) + uint(params.grid.y) * uint(layer));
  // The distance is at least the plane's: a triangle whose plane lies farther than the voxel's nearest
  // distance so far (with the same slack) can neither lower it nor tie with it. In pass 1 another group
  // may lower the word at any time; whatever this read sees is at least the final minimum, so the test
  // only prunes less, never wrongly.
  uint nearest = nearest_distance[slot];
  if (nearest != 0u && plane > uintBitsToFloat(~nearest) + 0.01) return;
#ifdef NEAREST_TRIANGLE
  if (nearest == 0u) return;  // no triangle within the band: pass 1 found none
#endif
  float d = triangle_distance(p, t);
  if (!(d < params.band.x)) return;
#ifdef NEAREST_TRIANGLE
  if (nearest == ~floatBitsToUint(d)) atomicMax(nearest_triangle[slot], ~record.x);
#else
  atomicMax(nearest_distance[slot], ~floatBitsToUint(d));
#endif
}
