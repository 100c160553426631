#version 450
#extension GL_GOOGLE_include_directive : require
// Contact candidate lists (sim/contact_lists.h), step 2 of a list build, after the hashed grid of the
// same positions: each particle's partners of other bodies whose surfaces lie within the skin of its
// own, |xi - xj| < ri + rj + cut-off, in ascending GPU index (sim/candidates.glsl), skipping pairs of
// which neither body can move. Column-major, so that a warp reading its particles' k-th candidates
// reads consecutive words: list[i] = the count n, list[(k + 1) N + i] = candidate k < n. A particle
// with more than K candidates stores K + 1 and, in rows 1-3, the grid cell it was found in: the
// contact kernel walks the grid for it (still valid for it: the cell is largest diameter + skin).
// The positions are kept as the build's (TS_SIM_BUILD_POSITION) for the displacement test.
#include "common/dispatch.glsl"
#include "common/bindings.h"
#include "sim/bindings.h"
#include "sim/precision.glsl"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_PARTICLE_POSITION) readonly buffer P { vec4 particle_position[]; };
layout(std430, binding = TS_GRID_CELL_START) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = TS_GRID_SORTED) readonly buffer Sorted { uint sorted_ids[]; };
layout(std430, binding = TS_SIM_PARTICLE_INFO) readonly buffer I { uvec4 particle_info[]; };
layout(std430, binding = TS_SIM_BODY_POSITION) readonly buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SIM_LIST) writeonly buffer L { uint list[]; };
layout(std430, binding = TS_SIM_BUILD_POSITION) writeonly buffer B { vec4 build_position[]; };
layout(std430, binding = TS_SIM_COUNTERS) buffer C { uint counters[]; };
#include "sim/candidates.glsl"
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform ListBlock { SimListParams params; };

void main() {
  uint i = dispatch_item();
  uint particles = params.sizes.x, capacity = params.sizes.z;
  if (i >= particles) return;
  vec4 xi = particle_position[i];
  build_position[i] = xi;
  uint body_i = particle_info[i].x;
  bool fixed_i = body_position[body_i].w == 0.0;
  ivec3 cell = cell_of_position(xi.xyz, params.lengths.x);
  begin_walk(cell, params.sizes.y, particles);
  uint n = 0u;
  for (uint j = next_candidate(); j != TS_SIM_WALK_DONE; j = next_candidate()) {
    uint body_j = particle_info[j].x;
    if (body_j == body_i || (fixed_i && body_position[body_j].w == 0.0)) continue;
    vec4 xj = particle_position[j];
    if (distance(xi.xyz, xj.xyz) >= xi.w + xj.w + params.lengths.z) continue;
    if (n == capacity) {
      n = capacity + 1u;
      break;
    }
    list[(n + 1u) * particles + i] = j;
    ++n;
  }
  list[i] = n;
  if (n > capacity) {
    list[particles + i] = uint(cell.x);
    list[2u * particles + i] = uint(cell.y);
    list[3u * particles + i] = uint(cell.z);
    atomicAdd(counters[TS_SIM_COUNTER_LIST_OVERFLOWS], 1u);  // integer counts: order-free
  }
}
