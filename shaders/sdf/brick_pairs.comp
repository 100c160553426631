#version 450
#extension GL_GOOGLE_include_directive : require
// Compute scan conversion, the triangle/brick pairs made on the GPU (sdf/compute_scan.h,
// BrickPairGenerator), after NanoVDB's CUDA mesh-to-grid: counts, a prefix sum and a scatter instead
// of the host's loop. One invocation per triangle, three variants:
//   ROW_SPANS: the brick rows (brick z) its box grown by the margin spans (0 when it misses the grid
//     or is degenerate). The host scans these in place: each triangle's first "triangle row" slot.
//   COUNT: per spanned row, the bricks it reaches; one atomicAdd of that count to the row's total,
//     whose old value (the triangle's first place within the row) goes to its triangle-row slot.
//   SCATTER: with the rows' first pairs (the host's prefix sum of the row totals), each reached brick
//     goes to row start + the triangle's place + how many it reached before in that row.
// Pairs end up grouped by row; within a row, triangles follow the order the atomics ran in. The
// scan passes take an atomic minimum of the distance bits and then the least triangle index, so the
// field does not depend on that order (tests/sdf/compute_scan_test.cpp).
// The brick test is sdf/compute_scan.cpp's host pairing operation for operation (`precise`, no
// contraction into fused multiply-adds), so both make the same set of pairs.
#if !defined(ROW_SPANS) && !defined(COUNT) && !defined(SCATTER)
#define SCATTER 1  // the build's check compiles the file without a variant
#endif
#include "common/dispatch.glsl"
#include "common/layouts.h"
#include "sdf/bindings.h"
layout(local_size_x = 64) in;
layout(std430, binding = TS_SDF_TRIANGLES) readonly buffer Triangles { SdfTriangle triangles[]; };
#ifdef ROW_SPANS
layout(std430, binding = TS_SDF_PAIR_SPANS) writeonly buffer Spans { uint spans[]; };
#else
layout(std430, binding = TS_SDF_PAIR_SPANS) readonly buffer Spans { uint spans[]; };
#endif
// RowTotals: per brick row, the counts COUNT adds, then (scanned on the host) the starts SCATTER reads;
// one block name for the one buffer in both variants (tests/gpu/bindings_test.cpp).
#ifdef COUNT
layout(std430, binding = TS_SDF_PAIR_TRIANGLE_ROWS) writeonly buffer TriangleRows { uint triangle_rows[]; };
layout(std430, binding = TS_SDF_PAIR_ROW_COUNTS) coherent buffer RowTotals { uint row_counts[]; };
#endif
#ifdef SCATTER
layout(std430, binding = TS_SDF_PAIR_TRIANGLE_ROWS) readonly buffer TriangleRows { uint triangle_rows[]; };
layout(std430, binding = TS_SDF_PAIR_ROW_COUNTS) readonly buffer RowTotals { uint row_starts[]; };
layout(std430, binding = TS_SDF_PAIRS_OUT) writeonly buffer Pairs { uvec2 pairs[]; };
#endif
#include "common/params.h"
layout(std140, binding = TS_SDF_PAIR_PARAMS) uniform BrickPairBlock { BrickPairParams params; };

float dot3(vec3 a, vec3 b) {
  precise float r = a.x * b.x + a.y * b.y + a.z * b.z;
  return r;
}

// |from_start - edge * s|^2: the squared distance to the point at s along an edge.
float edge_distance2(vec3 from_start, vec3 edge, float s) {
  precise vec3 r = from_start - edge * s;
  return dot3(r, r);
}

// Squared distance from p to triangle abc (Ericson 5.1.5, the same region tests as
// sdf/closest_point.glsl); in the face region the distance to the plane of unit normal n.
float triangle_distance2(vec3 p, vec3 a, vec3 b, vec3 c, vec3 n) {
  precise vec3 ab = b - a, ac = c - a, ap = p - a, bp = p - b, cp = p - c;
  precise float d1 = dot3(ab, ap), d2 = dot3(ac, ap), d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  precise float d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d1 <= 0.0 && d2 <= 0.0) return dot3(ap, ap);
  if (d3 >= 0.0 && d4 <= d3) return dot3(bp, bp);
  if (d6 >= 0.0 && d5 <= d6) return dot3(cp, cp);
  precise float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return edge_distance2(ap, ab, d1 / (d1 - d3));
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return edge_distance2(ap, ac, d2 / (d2 - d6));
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
    return edge_distance2(bp, c - b, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
  precise float h = dot3(ap, n);
  return h * h;
}

// The bricks of t's box grown by the margin, clamped to the grid (in float before the conversion,
// which is undefined out of int's range); false when the box misses the grid or t is degenerate.
bool brick_box(SdfTriangle t, out ivec3 b0, out ivec3 b1) {
  b0 = ivec3(0);
  b1 = ivec3(-1);
  if (t.face_normal.w == 0.0) return false;
  vec3 lo = min(min(t.vertex[0].xyz, t.vertex[1].xyz), t.vertex[2].xyz) - params.reach.x;
  vec3 hi = max(max(t.vertex[0].xyz, t.vertex[1].xyz), t.vertex[2].xyz) + params.reach.x;
  if (any(lessThan(hi, vec3(0.0))) || any(greaterThan(lo, vec3(params.grid.xyz - 1)))) return false;
  vec3 top = vec3(params.bricks.xyz - 1);
  float side = float(params.grid.w);
  b0 = ivec3(clamp(floor(lo / side), vec3(0.0), top));
  b1 = ivec3(clamp(floor(hi / side), vec3(0.0), top));
  return true;
}

// Whether a voxel centre of brick b may lie within the margin of t: the centre within `plane_reach`
// of t's plane and within sqrt(reach.z) of t.
bool brick_reached(SdfTriangle t, float plane_reach, ivec3 b) {
  precise vec3 centre = vec3(b) * float(params.grid.w) + params.reach.y;
  vec3 n = t.face_normal.xyz;
  if (abs(dot3(n, centre - t.vertex[0].xyz)) > plane_reach) return false;
  return !(triangle_distance2(centre, t.vertex[0].xyz, t.vertex[1].xyz, t.vertex[2].xyz, n) > params.reach.z);
}

void main() {
  uint index = dispatch_item();
  if (index >= params.counts.x) return;
  SdfTriangle t = triangles[index];
  ivec3 b0, b1;
  bool spans_grid = brick_box(t, b0, b1);
#ifdef ROW_SPANS
  spans[index] = spans_grid ? uint(b1.z - b0.z + 1) : 0u;
#else
  if (!spans_grid) return;
  vec3 n = abs(t.face_normal.xyz);
  precise float plane_reach = params.reach.x + params.reach.y * (n.x + n.y + n.z);
  uint first = spans[index];
  for (int bz = b0.z; bz <= b1.z; ++bz) {
    uint slot = first + uint(bz - b0.z);
#ifdef COUNT
    uint reached = 0u;
    for (int by = b0.y; by <= b1.y; ++by)
      for (int bx = b0.x; bx <= b1.x; ++bx)
        if (brick_reached(t, plane_reach, ivec3(bx, by, bz))) ++reached;
    triangle_rows[slot] = reached == 0u ? 0u : atomicAdd(row_counts[bz], reached);
#else
    uint place = row_starts[bz] + triangle_rows[slot];
    for (int by = b0.y; by <= b1.y; ++by)
      for (int bx = b0.x; bx <= b1.x; ++bx)
        if (brick_reached(t, plane_reach, ivec3(bx, by, bz))) pairs[place++] = uvec2(index, uint(bx) | (uint(by) << 16));
#endif
  }
#endif
}
