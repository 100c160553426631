#version 450
#extension GL_GOOGLE_include_directive : require
// Coverage certificate, one level of the subdivision (docs/coverage-certificate.md). For each
// sub-triangle T of the queue:
//   U = min over centres p of max over T's corners v of |v - p|: the distance to one centre is convex,
//       so its maximum over T is at a corner, and every point of T lies within U of that centre:
//       U bounds the distance from T to the nearest centre from above;
//   n = distance from T's centroid to the nearest centre: a point of the surface at n from every
//       centre, so the covering radius is at least n (a witness);
// then T's fate: covered (U <= radius: one ball holds its corners, so all of it), split in four,
// or final and uncovered. Centres come from the hashed grid (cell = radius) in cubic shells of cells
// around the centroid until no unvisited centre can lower U (see the search below).
#include "common/dispatch.glsl"
#include "common/hash_grid.glsl"
#include "common/bindings.h"
#include "common/layouts.h"
#include "sampler/bindings.h"

layout(local_size_x = 64) in;
layout(std430, binding = TS_CERT_CENTRES) readonly buffer Centres { vec4 centres[]; };
layout(std430, binding = TS_CERT_TRIANGLES) readonly buffer Triangles { CertTriangle triangles[]; };
layout(std430, binding = TS_CERT_QUEUE) readonly buffer Queue { uvec4 queue[]; };
layout(std430, binding = TS_GRID_CELL_COUNT) readonly buffer CellCount { uint cell_count[]; };
layout(std430, binding = TS_GRID_CELL_START) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = TS_GRID_SORTED) readonly buffer Sorted { uint sorted_ids[]; };
layout(std430, binding = TS_CERT_SPLITS) writeonly buffer Splits { uint splits[]; };
layout(std430, binding = TS_CERT_UNCOVERED) writeonly buffer Uncovered { uint uncovered[]; };
layout(std430, binding = TS_CERT_BOUNDS) writeonly buffer Bounds { vec4 bounds[]; };
// [0]: largest U of a final sub-triangle, [1]: largest witness n, both as float bits (non-negative
// floats order like their bits, so atomicMax on uints is exact and order-independent); [2], [3] unused.
layout(std430, binding = TS_CERT_TOTALS) buffer Totals { uint totals[]; };

#include "common/params.h"
layout(std140, binding = TS_SAMPLER_PARAMS) uniform CertifyBlock { CertifyParams params; };

const int kMaxLevel = 24;  // i, j and the step 2^-level stay exact in float

vec3 grid_point(CertTriangle t, uint a, uint b, int level) {
  return t.corner.xyz + (t.edge1.xyz * ldexp(float(a), -level) + t.edge2.xyz * ldexp(float(b), -level));
}

void corners_of(uvec4 id, CertTriangle t, out vec3 v0, out vec3 v1, out vec3 v2) {
  int level = int(id.y & 0xffu);
  bool down = (id.y >> 8) != 0u;
  uint i = id.z, j = id.w;
  v0 = down ? grid_point(t, i + 1u, j, level) : grid_point(t, i, j, level);
  v1 = down ? grid_point(t, i, j + 1u, level) : grid_point(t, i + 1u, j, level);
  v2 = grid_point(t, down ? i + 1u : i, j + 1u, level);
}

float squared(vec3 d) { return dot(d, d); }


struct Search {
  float best2;     // U^2 so far [m^2]
  float nearest2;  // n^2 so far [m^2]
};

// Every centre in one hashed cell (a bucket shared with other cells only adds candidates).
void visit_cell(ivec3 cell, vec3 v0, vec3 v1, vec3 v2, vec3 g, inout Search s) {
  uint h = hash_cell(cell, params.sizes.y);
  uint begin = cell_start[h], end = begin + cell_count[h];
  for (uint k = begin; k < end; ++k) {
    vec3 p = centres[sorted_ids[k]].xyz;
    s.best2 = min(s.best2, max(max(squared(v0 - p), squared(v1 - p)), squared(v2 - p)));
    s.nearest2 = min(s.nearest2, squared(g - p));
  }
}

// The cells at Chebyshev distance R from c (R = 0: c itself).
void visit_shell(ivec3 c, int R, vec3 v0, vec3 v1, vec3 v2, vec3 g, inout Search s) {
  for (int dz = -R; dz <= R; ++dz)
    for (int dy = -R; dy <= R; ++dy) {
      // Rows inside the shell's faces hold only its two end cells.
      int step = (abs(dz) == R || abs(dy) == R) ? 1 : 2 * R;
      for (int dx = -R; dx <= R; dx += step) visit_cell(c + ivec3(dx, dy, dz), v0, v1, v2, g, s);
    }
}

void main() {
  uint e = dispatch_item();
  if (e == params.sizes.x) {  // the extra zero that makes the scanned value at `count` the total
    splits[e] = 0u;
    uncovered[e] = 0u;
  }
  if (e >= params.sizes.x) return;
  uvec4 id = queue[e];
  CertTriangle t = triangles[id.x];
  int level = int(id.y & 0xffu);
  vec3 v0, v1, v2;
  corners_of(id, t, v0, v1, v2);
  vec3 g = (v0 + v1 + v2) / 3.0;

  // Shells around the centroid's cell. After shell R every centre within R cells (less the slack) of
  // g has been seen; an unseen one is farther from g, hence (|g - p| <= max_v |v - p|, convexity)
  // from some corner, so it cannot lower U once U is within that radius.
  const float infinity = uintBitsToFloat(0x7f800000u);
  Search s = Search(infinity, infinity);  // U is infinite until a centre is seen
  ivec3 c = cell_of_position(g, params.lengths.x);
  float searched = 0.0;  // radius around g within which every centre was seen [m]
  for (int R = 0; R <= params.search.x; ++R) {
    visit_shell(c, R, v0, v1, v2, g, s);
    searched = max(float(R) * params.lengths.x - params.lengths.y, 0.0);
    if (s.best2 <= searched * searched) break;
  }
  float bound = sqrt(s.best2);
  // Unseen centres are farther than `searched` from g: n is exact within that radius, and at least it.
  float witness = min(sqrt(s.nearest2), searched);
  float rho = sqrt(max(max(squared(v0 - g), squared(v1 - g)), squared(v2 - g)));
  float edge = ldexp(t.edge1.w, -level);

  bool covered = bound <= params.lengths.z;
  // Every point of T is farther than the radius from every centre: splitting cannot find cover.
  bool wholly_uncovered = witness - rho > params.lengths.z;
  bool at_floor = edge <= params.lengths.w || level >= kMaxLevel || params.sizes.z != 0u;
  // The search ended at max_shells before it could rule out a nearer centre (U may be infinite).
  // Either T is large (its corners lie beyond the search, though a centre is near its centroid) or
  // it sits in a hole deeper than the search. A large T is split like an undecided one: its children
  // are smaller, their searches complete. One in a deep hole is split only while it is larger than
  // the search, so its children may find a centre; a final one is bounded again by the host from its
  // exact nearest centre.
  bool complete = bound <= searched;
  bool near_centre = s.nearest2 <= searched * searched;  // g's nearest centre was seen
  float resolution = params.refine.z > params.lengths.z ? params.refine.x : params.lengths.w;
  bool split;
  if (!complete) {
    split = !at_floor && !wholly_uncovered && (rho > searched || (near_centre && edge > resolution));
  } else {
    bool undecided = !covered && !wholly_uncovered && edge > resolution;
    split = !at_floor && (bound > params.refine.z + params.refine.y || undecided);
  }
  splits[e] = split ? 4u : 0u;
  uncovered[e] = !split && !covered ? 1u : 0u;
  bounds[e] = vec4(bound, witness, complete ? 1.0 : 0.0, edge);
  if (!split && (covered || complete)) atomicMax(totals[0], floatBitsToUint(bound));
  atomicMax(totals[1], floatBitsToUint(witness));
}
