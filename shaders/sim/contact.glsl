// The contact model (thesis chapter 3, formulas in shared/notes/formulas.md), between a sphere i and
// a sphere j (or an infinitely massive wall). Returns the force on i.
#ifndef TETRASAND_SIM_CONTACT_GLSL
#define TETRASAND_SIM_CONTACT_GLSL
#include "common/layouts.h"
#include "sim/precision.glsl"

#define TS_DAMPING_TSUJI 0
#define TS_DAMPING_THESIS 1

struct ContactPair {
  real radius_i, radius_j;    // [m]; radius_j = 0 means a flat wall (R* = radius_i)
  real effective_mass;        // m* = m_i m_j / (m_i + m_j) of the two bodies [kg]
  SimMaterial mi, mj;
};

real effective_modulus(SimMaterial a, SimMaterial b) {
  // 1/E* = (1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b
  return 1.0 / ((1.0 - real(a.elastic.y) * real(a.elastic.y)) / real(a.elastic.x) +
                (1.0 - real(b.elastic.y) * real(b.elastic.y)) / real(b.elastic.x));
}

// delta: overlap [m] > 0; n: unit normal from j to i; vc: velocity of i's contact point relative to j's.
real3 contact_force(ContactPair c, real delta, real3 n, real3 vc, int damping_model) {
  real r_eff = c.radius_j > 0.0 ? c.radius_i * c.radius_j / (c.radius_i + c.radius_j) : c.radius_i;
  real e_star = effective_modulus(c.mi, c.mj);
  real k_n = 4.0 / 3.0 * e_star * sqrt(r_eff);             // eq. 3.19
  real delta_dot = -dot(vc, n);                             // > 0 while approaching
  real sqrt_delta = sqrt(delta);
  real elastic = k_n * delta * sqrt_delta;                  // k_n delta^(3/2)
  real damping;
  if (damping_model == TS_DAMPING_TSUJI) {
    // Constant restitution (Tsuji; LAMMPS hertz/material damping tsuji), pairwise mean e.
    real e = 0.5 * (real(c.mi.elastic.z) + real(c.mj.elastic.z));
    real log_e = real(log(float(max(e, 1e-6))));  // log has no double overload
    real beta = log_e / sqrt(log_e * log_e + 9.869604401089358);
    real s_n = 2.0 * e_star * sqrt(r_eff * delta);
    damping = -2.0 * sqrt(5.0 / 6.0) * beta * sqrt(s_n * c.effective_mass) * delta_dot;
  } else {
    // Thesis eq. 3.27: gamma_n delta^(1/2) delta_dot, gamma_n a material constant (pairwise mean).
    real gamma_n = 0.5 * (real(c.mi.damping.y) + real(c.mj.damping.y));
    damping = gamma_n * sqrt_delta * delta_dot;
  }
  real normal = max(elastic + damping, 0.0);  // contacts push, never pull
  // Eq. 3.28: viscous tangential force capped by Coulomb friction (no history spring).
  real3 vs = vc - dot(vc, n) * n;
  real speed = length(vs);
  real3 tangential = real3(0.0);
  if (speed > 1e-12) {
    real mu = 0.5 * (real(c.mi.elastic.w) + real(c.mj.elastic.w));
    real gamma_s = 0.5 * (real(c.mi.damping.x) + real(c.mj.damping.x));
    tangential = -min(mu * normal, gamma_s * speed) * vs / speed;
  }
  return normal * n + tangential;
}
#endif
