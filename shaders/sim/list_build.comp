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
// Pairs joined by an intact bond are left to the bond (sim/bond_forces.comp), as the CPU lists do: no
// candidates; a pair whose bond broke is listed with TS_SIM_LIST_BROKEN_BOND set, so the contact
// kernel looks up its rest overlap for such pairs only. An overflowing particle lists its intact bonded partners instead, in row 4 (how many)
// and rows 5 on, for the contact kernel's grid walk to skip; when they do not fit either, it is
// counted (TS_SIM_COUNTER_BOND_EXCLUSIONS_LOST) and the run stops at the next statistics.
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
layout(std430, binding = TS_SIM_BOND_PAIR) readonly buffer Pairs { uvec4 bond_pair[]; };
layout(std430, binding = TS_SIM_BOND_CSR) readonly buffer Csr { uint bond_csr[]; };
#include "sim/candidates.glsl"
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform ListBlock { SimListParams params; };

// Particle i's bonds (its CSR entries [first, last)): BOND_NONE when none joins it to j, else whether
// the one that does is intact or broken.
#define BOND_NONE 0u
#define BOND_INTACT 1u
#define BOND_BROKEN 2u
uint bond_with(uint i, uint j, uint first, uint last, uint particles) {
  for (uint e = first; e < last; ++e) {
    uvec4 pair = bond_pair[bond_csr[particles + 1u + TS_SIM_BOND_CSR_STRIDE * e]];
    if ((pair.x == j || pair.y == j) && j != i) return pair.z != 0u ? BOND_INTACT : BOND_BROKEN;
  }
  return BOND_NONE;
}

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
  uint world_id = particle_info[i].z;
  uint bonds_first = bond_csr[world_id], bonds_last = bond_csr[world_id + 1u];
  uint n = 0u;
  for (uint j = next_candidate(); j != TS_SIM_WALK_DONE; j = next_candidate()) {
    uint body_j = particle_info[j].x;
    if (body_j == body_i || (fixed_i && body_position[body_j].w == 0.0)) continue;
    vec4 xj = particle_position[j];
    if (distance(xi.xyz, xj.xyz) >= xi.w + xj.w + params.lengths.z) continue;
    uint bond = bonds_first != bonds_last ? bond_with(i, j, bonds_first, bonds_last, particles) : BOND_NONE;
    if (bond == BOND_INTACT) continue;
    if (n == capacity) {
      n = capacity + 1u;
      break;
    }
    list[(n + 1u) * particles + i] = bond == BOND_BROKEN ? j | TS_SIM_LIST_BROKEN_BOND : j;
    ++n;
  }
  list[i] = n;
  if (n > capacity) {
    list[particles + i] = uint(cell.x);
    list[2u * particles + i] = uint(cell.y);
    list[3u * particles + i] = uint(cell.z);
    atomicAdd(counters[TS_SIM_COUNTER_LIST_OVERFLOWS], 1u);  // integer counts: order-free
    uint m = 0u;
    for (uint e = bonds_first; e < bonds_last; ++e) {
      uvec4 pair = bond_pair[bond_csr[particles + 1u + TS_SIM_BOND_CSR_STRIDE * e]];
      if (pair.z == 0u) continue;
      if (4u + m < capacity) list[(5u + m) * particles + i] = pair.x == i ? pair.y : pair.x;
      ++m;
    }
    list[4u * particles + i] = m;
    if (4u + m > capacity) atomicAdd(counters[TS_SIM_COUNTER_BOND_EXCLUSIONS_LOST], 1u);
  }
}
