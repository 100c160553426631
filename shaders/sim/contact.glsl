// The contact model (thesis chapter 3; shared/notes/formulas.md), line for line the GLSL twin of
// sim/contact_model.h (hertz_contact_force, sphere_sphere_contact, sphere_wall_contact), so the GPU
// and the CPU reference agree to float rounding. The force acts on sphere 1 at the middle of the
// overlap, the same point for both partners, so every pair conserves angular momentum.
#ifndef TETRASAND_SIM_CONTACT_GLSL
#define TETRASAND_SIM_CONTACT_GLSL
#include "common/layouts.h"
#include "sim/precision.glsl"

#define TS_DAMPING_TSUJI 0
#define TS_DAMPING_THESIS 1

// n: unit normal towards sphere 1; delta: overlap [m] > 0; vc: contact velocity of 1 relative to 2.
real3 hertz_contact_force(real3 n, real delta, real3 vc, real effective_radius, real effective_mass, SimPair c,
                          int damping_model) {
  real e_star = real(c.coefficients.x);
  real k_n = 4.0 / 3.0 * e_star * sqrt(effective_radius);  // eq. 3.19 [N/m^1.5]
  real delta_dot = -dot(vc, n);                            // > 0 while approaching [m/s]
  real damping;
  if (damping_model == TS_DAMPING_TSUJI) {
    real s_n = 2.0 * e_star * sqrt(effective_radius * delta);
    damping = real(2.0 * sqrt(5.0 / 6.0) / sqrt(5.0)) * real(c.coefficients.w) * sqrt(s_n * effective_mass) * delta_dot;
  } else {
    // Thesis eq. 3.27 with gamma_n = c (m*^2 k_n^3 / v_ref)^(1/5); pow has no double overload.
    real gamma_n = real(c.coefficients.w) *
                   real(pow(float(effective_mass * effective_mass * k_n * k_n * k_n / real(c.extra.x)), 0.2));
    damping = gamma_n * sqrt(delta) * delta_dot;
  }
  real normal = max(real(0.0), k_n * delta * sqrt(delta) + damping);  // contacts push, never pull
  real3 vs = vc - dot(vc, n) * n;  // eq. 3.28: viscous slip force capped by Coulomb
  real slip = length(vs);
  real3 tangential = real3(0.0);
  if (slip > 0.0) tangential = -(min(real(c.coefficients.y) * normal, real(c.coefficients.z) * slip) / slip) * vs;
  return normal * n + tangential;
}
#endif
