#version 450
#extension GL_GOOGLE_include_directive : require
// Step 3: contact forces gathered per particle over its contact candidate list (list_build.comp), in
// ascending GPU index whenever the list was built, so there are no float atomics and results are
// bitwise reproducible, also across a rebuild at another step. A particle whose candidates overflowed
// the list walks the grid of the same build instead, in the same order (sim/candidates.glsl). Only
// particles of different bodies touch; walls are implicit (no particle storage).
// With the spring tangential model each dynamic particle keeps its contacts' springs in its own
// history slots (read at the start, rewritten in gather order), matched by partner id, as
// CpuStepper::visit_contacts does. At most 16 storage blocks (the per-stage minimum of GL 4.3).
// Scene-wide switches are compile-time specialisations (GpuStepper compiles one program per
// combination a loaded world uses; the shader cache keeps each): what is off costs no registers.
//   TS_CONTACT_SPRINGS      1: tangential springs (static friction), 0: viscous eq. 3.28
//   TS_CONTACT_DAMPING      TS_DAMPING_TSUJI (0) or TS_DAMPING_THESIS (1)
//   TS_CONTACT_WALLS        1: the world has smooth walls (planes or cylinders)
//   TS_CONTACT_PENETRATION  1: count dynamic particles that passed through a wall
//   TS_CONTACT_BONDS        1: the world has bonds; a broken bond's pair touches only past its rest overlap
// Without them (glslangValidator, the Params test) every switch is on, Tsuji damping.
#ifndef TS_CONTACT_SPRINGS
#define TS_CONTACT_SPRINGS 1
#endif
#ifndef TS_CONTACT_DAMPING
#define TS_CONTACT_DAMPING 0
#endif
#ifndef TS_CONTACT_WALLS
#define TS_CONTACT_WALLS 1
#endif
#ifndef TS_CONTACT_PENETRATION
#define TS_CONTACT_PENETRATION 1
#endif
#ifndef TS_CONTACT_BONDS
#define TS_CONTACT_BONDS 1
#endif
#include "common/dispatch.glsl"
#include "common/bindings.h"
#include "sim/bindings.h"
#include "common/layouts.h"
#include "sim/contact.glsl"
#include "sim/rigid.glsl"
// Work-group size rule: 128 for per-particle gathers like this one (enough warps per group to hide
// the dependent neighbour loads, small enough that a group's register file does not cap occupancy),
// 256 for the tree reductions (reduce_*.comp), which halve the partial count per level.
layout(local_size_x = 128) in;
layout(std430, binding = TS_GRID_CELL_START) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = TS_GRID_SORTED) readonly buffer Sorted { uint sorted_ids[]; };
layout(std430, binding = TS_SIM_PARTICLE_VELOCITY) readonly buffer V { real4 particle_velocity[]; };
layout(std430, binding = TS_SIM_PARTICLE_INFO) readonly buffer I { uvec4 particle_info[]; };
layout(std430, binding = TS_SIM_BODY_POSITION) readonly buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SIM_BODY_OMEGA) readonly buffer BW { real4 body_omega[]; };
layout(std430, binding = TS_SIM_PARTICLE_WRENCH) writeonly buffer F { real4 particle_wrench[]; };
layout(std430, binding = TS_SIM_PAIRS) readonly buffer M { SimPair pair_table[]; };
layout(std430, binding = TS_SIM_PLANES) readonly buffer Planes { SimPlane planes[]; };
layout(std430, binding = TS_SIM_CYLINDERS) readonly buffer Cylinders { SimCylinder cylinders[]; };
layout(std430, binding = TS_SIM_PARTICLE_STATS) writeonly buffer S { vec4 particle_stats[]; };
layout(std430, binding = TS_SIM_COUNTERS) buffer C { uint counters[]; };
layout(std430, binding = TS_SIM_LIST) readonly buffer L { uint list[]; };
#if TS_CONTACT_BONDS
layout(std430, binding = TS_SIM_BOND_CSR) readonly buffer Csr { uint bond_csr[]; };
#endif
#ifdef TS_FP64
layout(std430, binding = TS_SIM_PARTICLE_POSITION_EXACT) readonly buffer PX { dvec4 particle_position_exact[]; };
#define POSITION(k) particle_position_exact[k]
layout(std430, binding = TS_SIM_SPRINGS) buffer Springs { SimSpringSlots64 springs[]; };
#else
// The float positions only without TS_FP64: a declared block counts against the 16 even unused.
layout(std430, binding = TS_SIM_PARTICLE_POSITION) readonly buffer P { vec4 particle_position[]; };
#define POSITION(k) particle_position[k]
layout(std430, binding = TS_SIM_SPRINGS) buffer Springs { SimSpringSlots springs[]; };
#endif

#include "sim/candidates.glsl"
#include "common/params.h"
#ifdef TS_FP64
layout(std140, binding = TS_SIM_PARAMS) uniform ContactBlock { SimContactParams64 params; };
#else
layout(std140, binding = TS_SIM_PARAMS) uniform ContactBlock { SimContactParams params; };
#endif

#if TS_CONTACT_SPRINGS
// This particle's contact history: the old slots, read once, and how many new ones are written.
int old_partner[TS_SIM_SPRING_SLOTS];
real3 old_spring[TS_SIM_SPRING_SLOTS];  // state: `real` (sim/contact.glsl, spring_tangential_force)
uint slots_used = 0u, slot_overflows = 0u;

void load_springs(uint i) {
  for (uint s = 0u; s < TS_SIM_SPRING_SLOTS; ++s) {
    old_partner[s] = springs[i].partner[s / 4u][s % 4u];
    old_spring[s] = real3(springs[i].displacement[s].xyz);
  }
}
#endif

// The force of one touching contact; with springs, takes the contact's spring from the old slots
// (zero when new) and keeps it, advanced, in the next free slot (counted when none is left).
creal3 contact_force(uint i, bool with_springs, int partner, creal3 n, creal delta, creal3 vc, creal effective_radius,
                     creal effective_mass, SimPair c) {
#if TS_CONTACT_SPRINGS
  if (!with_springs) return hertz_contact_force(n, delta, vc, effective_radius, effective_mass, c, TS_CONTACT_DAMPING);
  real3 spring = real3(0.0);
  for (uint s = 0u; s < TS_SIM_SPRING_SLOTS; ++s)
    if (old_partner[s] == partner) spring = old_spring[s];
  creal3 f = hertz_spring_contact_force(n, delta, vc, effective_radius, effective_mass, c, TS_CONTACT_DAMPING,
                                        real(params.step.x), spring);
  if (slots_used == TS_SIM_SPRING_SLOTS) {
    ++slot_overflows;
  } else {
    springs[i].partner[slots_used / 4u][slots_used % 4u] = partner;
    springs[i].displacement[slots_used] = real4(spring, 0.0);
    ++slots_used;
  }
  return f;
#else
  return hertz_contact_force(n, delta, vc, effective_radius, effective_mass, c, TS_CONTACT_DAMPING);
#endif
}

#if TS_CONTACT_BONDS
// m: the rest overlap of the bond that joined world particles i (its CSR entries [first, last)) and
// world_j, 0 when none (intact bonds never get here: the lists leave their pairs out).
creal rest_overlap(uint first, uint last, uint world_j, uint particles) {
  for (uint e = first; e < last; ++e) {
    uint entry = particles + 1u + TS_SIM_BOND_CSR_STRIDE * e;
    if (bond_csr[entry + 1u] == world_j) return creal(uintBitsToFloat(bond_csr[entry + 2u]));
  }
  return 0.0;
}
#endif

// Particle i lies wholly behind the surface of smooth wall `slot` (planes, then cylinders): counted,
// and the wall keeps the lowest world particle id found behind it (as ~id, so 0 means none).
#if TS_CONTACT_WALLS && TS_CONTACT_PENETRATION
void note_penetration(uint i, uint slot) {
  atomicAdd(counters[TS_SIM_COUNTER_PENETRATIONS], 1u);
  atomicMax(counters[TS_SIM_COUNTER_WALL_SLOTS + slot], ~particle_info[i].z);
}
#endif

void main() {
  uint i = dispatch_item();
  if (i >= params.sizes.x) return;
  uint body_i = particle_info[i].x;
  real4 xi4 = POSITION(i);
  real3 xi = xi4.xyz;
  creal ri = creal(xi4.w);
  real3 vi = particle_velocity[i].xyz;
  creal3 wi = creal3(body_omega[body_i].xyz);
  real inv_mass_i = body_position[body_i].w;
  uint pair_row = particle_info[i].y * params.materials.x;
  real3 force = real3(0.0), torque = real3(0.0);
  creal3 arm_i = creal3(xi - body_position[body_i].xyz);  // relative in double, then float (mixed)
  // Static and kinematic particles keep no springs (their partners hold the contact's), as on the CPU.
  bool with_springs = TS_CONTACT_SPRINGS != 0 && inv_mass_i > 0.0;
#if TS_CONTACT_SPRINGS
  if (with_springs) load_springs(i);
#endif

  float pair_contacts = 0.0, walls = 0.0, clamps = 0.0, worst_overlap = 0.0;
  creal overlap_cap = creal(params.limits.y);
  // The list's candidates (rows 1..n, column-major), or past capacity the grid walk from the cell the
  // build stored in rows 1-3: both in ascending index, one fixed order whenever the list was built.
  uint particles = params.sizes.x, listed = list[i];
  bool from_list = listed <= params.lists.x;
  uint bonded_partners = 0u;  // the walk skips these (list_build.comp, rows 5 on): their bonds carry them
#if TS_CONTACT_BONDS
  uint bonds_first = bond_csr[particle_info[i].z], bonds_last = bond_csr[particle_info[i].z + 1u];
#endif
  if (!from_list) {
    ivec3 cell = ivec3(int(list[particles + i]), int(list[2u * particles + i]), int(list[3u * particles + i]));
    begin_walk(cell, params.sizes.y, particles);
    bonded_partners = min(list[4u * particles + i], params.lists.x - 4u);
  }
  for (uint k = 0u;; ++k) {
    uint j;
    bool broken_bond;  // whether the pair may have a rest overlap to look up (rest_overlap)
    if (from_list) {
      if (k >= listed) break;
      uint entry = list[(k + 1u) * particles + i];
      j = entry & ~TS_SIM_LIST_BROKEN_BOND;
      broken_bond = (entry & TS_SIM_LIST_BROKEN_BOND) != 0u;  // the build found the bond
    } else {
      j = next_candidate();
      if (j == TS_SIM_WALK_DONE) break;
      broken_bond = true;  // the walk does not know: look it up
    }
    uint body_j = particle_info[j].x;
    if (body_j == body_i) continue;  // the grid walk's own body (lists hold other bodies only)
    bool bonded = false;
    for (uint b = 0u; b < bonded_partners; ++b) bonded = bonded || list[(5u + b) * particles + i] == j;
    if (bonded) continue;
    real inv_mass_j = body_position[body_j].w;
    if (inv_mass_i == 0.0 && inv_mass_j == 0.0) continue;  // neither body can move
    real4 xj4 = POSITION(j);
    // Mixed precision: the position and velocity differences in double, rounded once to float
    // (exact to float relative to the pair's separation and relative speed); the rest in float
    // but the overlap: radii and separation are each ~1000 small overlaps, so their float
    // difference would keep three or four digits of it. It is (reach^2 - |dx|^2) / (reach + |dx|)
    // with the numerator in `real`, for the pairs float cannot already tell apart.
    real3 dx = xi - xj4.xyz;
    creal3 d = creal3(dx);
    creal rj = creal(xj4.w);
    creal dist = length(d);
    if (dist >= (ri + rj) * 1.00001 || dist <= 0.0) continue;
    real reach = xi4.w + xj4.w;
    real gap2 = reach * reach - dot(dx, dx);
    if (gap2 <= 0.0) continue;
    creal raw = creal(gap2) / (creal(reach) + dist);
#if TS_CONTACT_BONDS
    if (bonds_first != bonds_last) {
      // Only a broken bond's pair searches i's bonds (a listed pair carries the build's answer, so an
      // unbonded partner of a bonded sphere no longer scans its whole row; docs/benchmarks/sim.md,
      // "Bonded spheres", measures the search on crumble.toml).
      if (broken_bond) raw -= rest_overlap(bonds_first, bonds_last, particle_info[j].z, particles);
      if (raw <= 0.0) continue;
    }
#endif
    creal3 n = d / dist;
    creal smaller = min(ri, rj);
    creal delta = min(raw, overlap_cap * smaller);
    creal3 arm1 = -(ri - 0.5 * raw) * n;
    creal3 arm2 = (rj - 0.5 * raw) * n;
    creal3 vc = creal3(vi - particle_velocity[j].xyz) + cross(wi, arm1) -
                cross(creal3(body_omega[body_j].xyz), arm2);
    creal3 f = contact_force(i, with_springs, int(j), n, delta, vc, ri * rj / (ri + rj),
                             creal(1.0 / (inv_mass_i + inv_mass_j)), pair_table[pair_row + particle_info[j].y]);
    force += real3(f);  // summed in `real`: double in the double pipelines
    torque += real3(cross(arm_i + arm1, f));
    if (i < j) {  // each pair is counted once, by its lower id
      pair_contacts += 1.0;
      worst_overlap = max(worst_overlap, float(delta / smaller));
      clamps += raw > delta ? 1.0 : 0.0;
    }
  }

#if TS_CONTACT_WALLS
  if (inv_mass_i > 0.0) {
    // Smooth walls in declaration order: planes, then cylinders (as the CPU reference). The overlap
    // in `real` (double in the double pipelines: the radius and the distance to the wall are each far
    // larger than it), the rest of the contact in `creal`.
    for (uint k = 0u; k < params.sizes.z; ++k) {
      SimPlane plane = planes[k];
      creal3 n = creal3(plane.normal_offset.xyz);
      creal raw = creal(xi4.w - (dot(real3(plane.normal_offset.xyz), xi) - real(plane.normal_offset.w)));
      if (raw <= 0.0) continue;
      if (plane.extent.w != 0.0) {
        creal3 rel = creal3(xi - real3(plane.extent.xyz));
        creal lateral = length(rel - dot(rel, n) * n);
        if (plane.extent.w > 0.0 ? lateral > creal(plane.extent.w) : lateral < creal(-plane.extent.w)) continue;
      }
#if TS_CONTACT_PENETRATION
      if (raw > 2.0 * ri) note_penetration(i, k);
#endif
      creal delta = min(raw, overlap_cap * ri);
      creal3 arm = -(ri - 0.5 * raw) * n;
      creal3 f = contact_force(i, with_springs, -1 - int(k), n, delta, creal3(vi) + cross(wi, arm), ri,
                               creal(1.0 / inv_mass_i), pair_table[pair_row + plane.material.x]);
      force += real3(f);
      torque += real3(cross(arm_i + arm, f));
      walls += 1.0;
      worst_overlap = max(worst_overlap, float(delta / ri));
      clamps += raw > delta ? 1.0 : 0.0;
    }
    for (uint k = 0u; k < params.sizes.w; ++k) {
      SimCylinder cyl = cylinders[k];
      if (xi.z < real(cyl.range.x) || xi.z > real(cyl.range.y)) continue;
      real2 radial_exact = xi.xy - real2(cyl.axis_radius.xy);
      real distance = length(radial_exact);
      if (distance <= 0.0) continue;
      creal2 radial = creal2(radial_exact);
      creal raw = creal(xi4.w - (real(cyl.axis_radius.w) - distance));
      if (raw <= 0.0) continue;
      creal3 n = creal3(-radial / length(radial), 0.0);
#if TS_CONTACT_PENETRATION
      if (raw > 2.0 * ri) note_penetration(i, params.sizes.z + k);
#endif
      creal delta = min(raw, overlap_cap * ri);
      creal3 arm = -(ri - 0.5 * raw) * n;
      creal3 f = contact_force(i, with_springs, -1 - int(params.sizes.z + k), n, delta, creal3(vi) + cross(wi, arm),
                               ri, creal(1.0 / inv_mass_i), pair_table[pair_row + cyl.material.x]);
      force += real3(f);
      torque += real3(cross(arm_i + arm, f));
      walls += 1.0;
      worst_overlap = max(worst_overlap, float(delta / ri));
      clamps += raw > delta ? 1.0 : 0.0;
    }
  }
#endif
#if TS_CONTACT_SPRINGS
  if (with_springs) {
    for (uint s = slots_used; s < TS_SIM_SPRING_SLOTS; ++s) springs[i].partner[s / 4u][s % 4u] = TS_SIM_NO_PARTNER;
    if (slot_overflows > 0u) atomicAdd(counters[2], slot_overflows);  // integer counts: order-free
  }
#endif
  particle_wrench[2u * i] = real4(force, 0.0);
  particle_wrench[2u * i + 1u] = real4(torque, 0.0);
  particle_stats[i] = vec4(pair_contacts, walls, worst_overlap, clamps);
}
