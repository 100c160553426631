#version 450
#extension GL_GOOGLE_include_directive : require
// Compute scan conversion of one slab (sdf/compute_scan.h): the slab's triangle/brick pairs turned into
// a triangle list per brick, then one pass per brick. Three variants:
//   BRICK_COUNT (one invocation per pair of the slab's brick rows): counts each brick's pairs in
//     brick_starts, the atomicAdd's old value being the pair's place among its brick's. The host then
//     scans brick_starts (exclusive, one entry past the slab's bricks): each brick's first triangle.
//   BRICK_SCATTER (one invocation per pair): puts the pair's triangle at its brick's start + its place.
//   default, the brick pass (one work group per brick of the slab, one invocation per voxel): each voxel
//     goes through its brick's triangles, keeps the least distance within the band, ties to the lower
//     triangle index, and stores that triangle's value (sdf/voxel_value.glsl, the fragment shader's)
//     into the slab target; the others keep its clear value. The least (distance, index) does not
//     depend on the order of the list, so the field is the same bytes whatever order the atomics and
//     the pair generation gave (tests/sdf/compute_scan_test.cpp).
// Against a pass per pair with atomic minima per voxel: one exact distance per voxel and triangle (not
// one per pass), no per-voxel buffers to clear, and only bricks with pairs do any work.
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
#ifndef BRICK
#define BRICK 4
#endif
#if defined(BRICK_COUNT) || defined(BRICK_SCATTER)
layout(local_size_x = 64) in;
layout(std430, binding = TS_SDF_PAIRS) readonly buffer Pairs { uvec2 pairs[]; };
layout(std430, binding = TS_SDF_PAIR_ROWS) readonly buffer PairRows { uint pair_rows[]; };
// BrickTotals: per brick, the counts BRICK_COUNT adds, then (scanned) the starts the other passes read;
// one block name for the one buffer in every variant (tests/gpu/bindings_test.cpp).
#ifdef BRICK_COUNT
layout(std430, binding = TS_SDF_PAIR_SLOTS) writeonly buffer PairSlots { uint pair_slots[]; };
layout(std430, binding = TS_SDF_BRICK_STARTS) coherent buffer BrickTotals { uint brick_counts[]; };
#else
layout(std430, binding = TS_SDF_PAIR_SLOTS) readonly buffer PairSlots { uint pair_slots[]; };
layout(std430, binding = TS_SDF_BRICK_STARTS) readonly buffer BrickTotals { uint brick_starts[]; };
layout(std430, binding = TS_SDF_BRICK_TRIANGLES) writeonly buffer BrickTriangles { uint brick_triangles[]; };
#endif
#else
layout(local_size_x = BRICK, local_size_y = BRICK, local_size_z = BRICK) in;
layout(std430, binding = TS_SDF_TRIANGLES) readonly buffer Triangles { SdfTriangle triangles[]; };
layout(std430, binding = TS_SDF_BRICK_STARTS) readonly buffer BrickTotals { uint brick_starts[]; };
layout(std430, binding = TS_SDF_BRICK_TRIANGLES) readonly buffer BrickTriangles { uint brick_triangles[]; };
layout(binding = TS_SDF_IMAGE_SLAB, rgba32f) writeonly uniform image2DArray slab;
#endif
#include "common/params.h"
layout(std140, binding = TS_SDF_COMPUTE_PARAMS) uniform ComputeScanBlock { ComputeScanParams params; };

// Bricks along x and y.
ivec2 brick_grid() { return (params.grid.xy + (BRICK - 1)) / BRICK; }

#if defined(BRICK_COUNT) || defined(BRICK_SCATTER)
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
  uint item = dispatch_item();
  if (item >= params.pairs.y) return;
  uint pair = params.pairs.x + item;
  uvec2 record = pairs[pair];
  uvec2 across = uvec2(brick_grid());
  uint row = uint(brick_row(pair) - params.slab.z);  // within the slab's rows
  uint brick = (row * across.y + (record.y >> 16)) * across.x + (record.y & 0xFFFFu);
#ifdef BRICK_COUNT
  pair_slots[item] = atomicAdd(brick_counts[brick], 1u);
#else
  brick_triangles[brick_starts[brick] + pair_slots[item]] = record.x;
#endif
}

#else
#include "sdf/voxel_value.glsl"

void main() {
  uint brick = dispatch_group();
  if (brick >= params.pairs.z) return;
  uint first = brick_starts[brick], end = brick_starts[brick + 1u];
  if (first == end) return;
  uvec2 across = uvec2(brick_grid());
  uint per_row = across.x * across.y;
  ivec3 b = ivec3(int(brick % across.x), int((brick % per_row) / across.x), int(brick / per_row) + params.slab.z);
  ivec3 voxel = b * BRICK + ivec3(gl_LocalInvocationID);
  int layer = voxel.z - params.slab.x;
  if (any(greaterThanEqual(voxel, params.grid.xyz)) || layer < 0 || layer >= params.slab.y) return;
  vec3 p = vec3(voxel);
  // Cheap rejections before the exact distance, which no voxel they drop can be within the band of, or
  // nearer than (or tied with) the best so far: outside the triangle's box grown by the band, or
  // farther from its plane than that best (the band at first). The slack (a hundredth of a voxel) keeps
  // float rounding of these bounds, ~1e-7 of the grid coordinate, from dropping a voxel whose exact
  // distance is just inside or ties.
  float reach = params.band.x + 0.01;
  float best = params.band.x;
  uint nearest = 0xFFFFFFFFu;  // none yet
  for (uint k = first; k < end; ++k) {
    uint index = brick_triangles[k];
    SdfTriangle t = triangles[index];
    vec3 lo = min(min(t.vertex[0].xyz, t.vertex[1].xyz), t.vertex[2].xyz) - reach;
    vec3 hi = max(max(t.vertex[0].xyz, t.vertex[1].xyz), t.vertex[2].xyz) + reach;
    float plane = abs(dot(p - t.vertex[0].xyz, t.face_normal.xyz));
    if (any(lessThan(p, lo)) || any(greaterThan(p, hi)) || plane > best + 0.01) continue;
    float d = triangle_distance(p, t);
    // Strictly inside the band; at an equal distance the lower index, never the list's order.
    if (d < best || (d == best && nearest != 0xFFFFFFFFu && index < nearest)) {
      best = d;
      nearest = index;
    }
  }
  if (nearest == 0xFFFFFFFFu) return;
  imageStore(slab, ivec3(voxel.xy, layer), voxel_value(p, triangles[nearest]));
}
#endif
