#version 450
#extension GL_GOOGLE_include_directive : require
// Step 3b, one invocation per bond after the contact forces: the bond's loads advanced over the step
// and its strengths checked (sim/bond.glsl, the twin of sim/bond_model.h), the load it puts on its two
// spheres written for bond_sums.comp, which adds them to each particle's wrench in a fixed order. A
// bond reads only its own state, so the bonds run in any order with the same bits. A bond that
// breaks is marked, counted, and forces a list rebuild at the next step (its pair becomes a contact
// candidate), all on the GPU: the host reads nothing per step.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "sim/bond.glsl"
layout(local_size_x = 128) in;
layout(std430, binding = TS_SIM_PARTICLE_POSITION) readonly buffer P { vec4 particle_position[]; };
layout(std430, binding = TS_SIM_PARTICLE_VELOCITY) readonly buffer V { real4 particle_velocity[]; };
layout(std430, binding = TS_SIM_PARTICLE_INFO) readonly buffer I { uvec4 particle_info[]; };
layout(std430, binding = TS_SIM_BODY_OMEGA) readonly buffer BW { real4 body_omega[]; };
layout(std430, binding = TS_SIM_BOND_PAIR) buffer Pairs { uvec4 bond_pair[]; };
layout(std430, binding = TS_SIM_BOND_STATE) buffer State { real4 bond_state[]; };
layout(std430, binding = TS_SIM_BOND_PARAMS) readonly buffer Params { real4 bond_params[]; };
layout(std430, binding = TS_SIM_BOND_LOAD) writeonly buffer Load { real4 bond_load[]; };
layout(std430, binding = TS_SIM_COUNTERS) buffer C { uint counters[]; };
layout(std430, binding = TS_SIM_LIST_STATE) buffer S { uint list_state[]; };
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

void write_load(uint k, creal3 force, creal3 moment, creal3 arm_a, creal3 arm_b) {
  bond_load[4u * k] = real4(force, 0.0);
  bond_load[4u * k + 1u] = real4(moment, 0.0);
  bond_load[4u * k + 2u] = real4(arm_a, 0.0);
  bond_load[4u * k + 3u] = real4(arm_b, 0.0);
}

void main() {
  uint k = dispatch_item();
  if (k >= params.sizes.x) return;
  uvec4 pair = bond_pair[k];
  if (pair.z == 0u) {
    write_load(k, creal3(0.0), creal3(0.0), creal3(0.0), creal3(0.0));
    return;
  }
  real4 g0 = bond_params[2u * k], g1 = bond_params[2u * k + 1u];
  BondParams g = BondParams(creal(g0.x), creal(g0.y), creal(g0.z), creal(g0.w), creal(g1.x), creal(g1.y), creal(g1.z),
                            creal(g1.w));
  real4 s0 = bond_state[2u * k], s1 = bond_state[2u * k + 1u];
  BondCarried s = BondCarried(s0.w, s0.xyz, s1.w, s1.xyz);
  real4 xa = POSITION(pair.x), xb = POSITION(pair.y);
  // Differences in `real`, rounded once to `creal` (as the contact kernel does).
  creal3 d = creal3(xa.xyz - xb.xyz);
  creal3 v_ab = creal3(particle_velocity[pair.x].xyz - particle_velocity[pair.y].xyz);
  creal3 w_a = creal3(body_omega[particle_info[pair.x].x].xyz), w_b = creal3(body_omega[particle_info[pair.y].x].xyz);
  creal3 force, moment, arm_a, arm_b;
  bool broke = bond_interaction(d, v_ab, w_a, creal(xa.w), w_b, creal(xb.w), g, creal(params.step.x), s, force, moment,
                                arm_a, arm_b);
  bond_state[2u * k] = real4(s.shear_force, s.normal_force);
  bond_state[2u * k + 1u] = real4(s.bending_moment, s.twisting_moment);
  write_load(k, force, moment, arm_a, arm_b);
  if (broke) {
    bond_pair[k].z = 0u;
    atomicAdd(counters[TS_SIM_COUNTER_BONDS_BROKEN], 1u);  // integer counts: order-free
    list_state[TS_SIM_LIST_FORCED] = 1u;                    // the pair is a contact candidate from the next step
  }
}
