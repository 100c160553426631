#version 450
#extension GL_GOOGLE_include_directive : require
// The bonds' elastic energy for statistics() [J], reduced on the GPU so an output reads back one
// double. Two passes of this kernel, both in double whatever the pipeline (as reduce_metrics.comp):
// TS_BOND_ENERGY_TOTAL 0, one invocation per bond: the energy of each intact bond, load^2 /
// (2 stiffness) of its four springs (sim::bond_energy, with the factors 1 / (2 stiffness) the host
// worked out in double), summed over each work group of 256 in a fixed tree into partial[group];
// TS_BOND_ENERGY_TOTAL 1, one work group: invocation t adds partials t, t + 256, ... in ascending
// order, the tree adds the 256 sums, and the total goes after the partials, at partial[groups]. A
// fixed order and no atomics: the same bits every run.
#include "common/dispatch.glsl"
#include "sim/bindings.h"
#include "sim/precision.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = TS_SIM_BOND_PAIR) readonly buffer Pairs { uvec4 bond_pair[]; };
layout(std430, binding = TS_SIM_BOND_STATE) readonly buffer State { real4 bond_state[]; };
layout(std430, binding = TS_SIM_BOND_ENERGY_FACTORS) readonly buffer Factors { dvec4 bond_energy_factors[]; };
layout(std430, binding = TS_SIM_BOND_ENERGY_PARTIALS) buffer Partials { double partial[]; };
#include "common/params.h"
layout(std140, binding = TS_SIM_PARAMS) uniform EnergyBlock { ItemCount params; };  // x: bonds
shared double scratch[256];

// Adds scratch[0..255] into scratch[0], pairwise in a fixed tree.
void sum_scratch(uint t) {
  for (uint stride = 128u; stride > 0u; stride >>= 1u) {
    barrier();
    if (t < stride) scratch[t] += scratch[t + stride];
  }
}

void main() {
  uint t = gl_LocalInvocationID.x;
  uint bonds = params.count.x, groups = (bonds + 255u) / 256u;
#if TS_BOND_ENERGY_TOTAL
  double sum = 0.0;
  for (uint g = t; g < groups; g += 256u) sum += partial[g];
  scratch[t] = sum;
  sum_scratch(t);
  if (t == 0u) partial[groups] = scratch[0];
#else
  uint k = dispatch_item();
  if (dispatch_group() >= groups) return;  // past the end: no partial
  double e = 0.0;
  if (k < bonds && bond_pair[k].z != 0u) {  // broken bonds hold no load (the CPU reference skips them)
    dvec4 s0 = dvec4(bond_state[2u * k]), s1 = dvec4(bond_state[2u * k + 1u]);
    // normal, shear, twisting, bending: TS_SIM_BOND_ENERGY_FACTORS' order
    dvec4 squares = dvec4(s0.w * s0.w, dot(s0.xyz, s0.xyz), s1.w * s1.w, dot(s1.xyz, s1.xyz));
    dvec4 terms = squares * bond_energy_factors[k];
    e = ((terms.x + terms.y) + terms.z) + terms.w;  // sim::bond_energy's order
  }
  scratch[t] = e;
  sum_scratch(t);
  if (t == 0u) partial[dispatch_group()] = scratch[0];
#endif
}
