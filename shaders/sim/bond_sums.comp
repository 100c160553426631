#version 450
#extension GL_GOOGLE_include_directive : require
// Step 3c, per particle after bond_forces.comp: the loads of the particle's bonds added to the wrench
// the contact kernel wrote, in ascending bond index (TS_SIM_BOND_CSR), as the CPU reference adds them
// after its contacts (sim/cpu_bonds.cpp): no float atomics, so the sums are the same bits every run.
// Sphere a of a bond takes the force and moment, sphere b their negatives, each with its own arm to
// the bond's centre; the torque is about the body's centre of mass, as the wrench holds it.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "sim/precision.glsl"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_PARTICLE_POSITION) readonly buffer P { vec4 particle_position[]; };
layout(std430, binding = TS_SIM_PARTICLE_INFO) readonly buffer I { uvec4 particle_info[]; };
layout(std430, binding = TS_SIM_PARTICLE_WRENCH) buffer F { real4 particle_wrench[]; };
layout(std430, binding = TS_SIM_BODY_POSITION) readonly buffer BP { real4 body_position[]; };
layout(std430, binding = TS_SIM_BOND_PAIR) readonly buffer Pairs { uvec4 bond_pair[]; };
layout(std430, binding = TS_SIM_BOND_CSR) readonly buffer Csr { uint bond_csr[]; };
layout(std430, binding = TS_SIM_BOND_LOAD) readonly buffer Load { real4 bond_load[]; };
#ifdef TS_FP64
layout(std430, binding = TS_SIM_PARTICLE_POSITION_EXACT) readonly buffer PX { dvec4 particle_position_exact[]; };
#define POSITION(k) particle_position_exact[k]
#else
#define POSITION(k) particle_position[k]
#endif
#include "common/params.h"
#ifdef TS_FP64
layout(std140, binding = TS_SIM_PARAMS) uniform BondBlock { SimBondParams64 params; };
#else
layout(std140, binding = TS_SIM_PARAMS) uniform BondBlock { SimBondParams params; };
#endif

void main() {
  uint i = dispatch_item();
  uint particles = params.sizes.y;
  if (i >= particles) return;
  uint world_id = particle_info[i].z;
  uint first = bond_csr[world_id], last = bond_csr[world_id + 1u];
  if (first == last) return;
  real3 force = particle_wrench[2u * i].xyz, torque = particle_wrench[2u * i + 1u].xyz;
  creal3 arm_i = creal3(POSITION(i).xyz - body_position[particle_info[i].x].xyz);
  for (uint e = first; e < last; ++e) {
    uint k = bond_csr[particles + 1u + TS_SIM_BOND_CSR_STRIDE * e];
    bool side_a = bond_pair[k].x == i;
    creal3 f = creal3(bond_load[4u * k].xyz), m = creal3(bond_load[4u * k + 1u].xyz);
    creal3 arm = creal3(bond_load[4u * k + (side_a ? 2u : 3u)].xyz);
    if (!side_a) {
      f = -f;
      m = -m;
    }
    force += real3(f);
    torque += real3(cross(arm_i + arm, f) + m);
  }
  particle_wrench[2u * i] = real4(force, 0.0);
  particle_wrench[2u * i + 1u] = real4(torque, 0.0);
}
