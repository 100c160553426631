#version 450
#extension GL_GOOGLE_include_directive : require
// The bonds' elastic energy for statistics() [J], per work group, as reduce_metrics.comp does the
// bodies' energies: in double whatever the pipeline, one invocation per bond, the energy of each intact
// bond, load^2 / (2 stiffness) of its four springs (sim::bond_energy, with the factors
// 1 / (2 stiffness) the host worked out in double), summed over each work group of 256 in a fixed tree
// into partial[group]; the host adds the partials in order. No atomics: the same bits every run.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "sim/precision.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SIM_BOND_PAIR) readonly buffer Pairs { uvec4 bond_pair[]; };
layout(std430, binding = TS_SIM_BOND_STATE) readonly buffer State { real4 bond_state[]; };
layout(std430, binding = TS_SIM_BOND_ENERGY_FACTORS) readonly buffer Factors { dvec4 bond_energy_factors[]; };
layout(std430, binding = TS_SIM_BOND_ENERGY_PARTIALS) writeonly buffer Partials { double partial[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform EnergyBlock { ItemCount params; };  // x: bonds
shared double scratch[256];

void main() {
  uint t = gl_LocalInvocationID.x, k = dispatch_item(), bonds = params.count.x;
  if (dispatch_group() * gl_WorkGroupSize.x >= bonds) return;  // past the end: no partial
  double e = 0.0;
  if (k < bonds && bond_pair[k].z != 0u) {  // broken bonds hold no load (the CPU reference skips them)
    dvec4 s0 = dvec4(bond_state[2u * k]), s1 = dvec4(bond_state[2u * k + 1u]);
    // normal, shear, twisting, bending: TS_SIM_BOND_ENERGY_FACTORS' order
    dvec4 squares = dvec4(s0.w * s0.w, dot(s0.xyz, s0.xyz), s1.w * s1.w, dot(s1.xyz, s1.xyz));
    dvec4 terms = squares * bond_energy_factors[k];
    e = ((terms.x + terms.y) + terms.z) + terms.w;  // sim::bond_energy's order
  }
  scratch[t] = e;
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    barrier();
    if (t < stride) scratch[t] += scratch[t + stride];
  }
  if (t == 0u) partial[dispatch_group()] = scratch[0];
}
