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

// The normal force magnitude [N]: Hertz (eq. 3.19) plus damping, never attractive.
// n: unit normal towards sphere 1; delta: overlap [m] > 0; vc: contact velocity of 1 relative to 2.
real hertz_normal_force(real3 n, real delta, real3 vc, real effective_radius, real effective_mass, SimPair c,
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
  return max(real(0.0), k_n * delta * sqrt(delta) + damping);  // contacts push, never pull
}

// Eq. 3.28: viscous slip force capped by Coulomb (normal + tangential force on sphere 1).
real3 hertz_contact_force(real3 n, real delta, real3 vc, real effective_radius, real effective_mass, SimPair c,
                          int damping_model) {
  real normal = hertz_normal_force(n, delta, vc, effective_radius, effective_mass, c, damping_model);
  real3 vs = vc - dot(vc, n) * n;
  real slip = length(vs);
  real3 tangential = real3(0.0);
  if (slip > 0.0) tangential = -(min(real(c.coefficients.y) * normal, real(c.coefficients.z) * slip) / slip) * vs;
  return normal * n + tangential;
}

// Static friction (sim::spring_tangential_force): the contact's elastic tangential displacement
// `spring` [m] is turned onto the tangent plane keeping its length, advanced by the slip over dt [s],
// and the force -k_t spring - gamma_s v_s, k_t = 8 G* sqrt(R* delta), is capped at mu F_n; while
// sliding, the spring is cut back to what the capped force implies.
real3 spring_tangential_force(real3 n, real delta, real3 vc, real effective_radius, real normal_force, SimPair c,
                              real dt, inout real3 spring) {
  real3 vs = vc - dot(vc, n) * n;
  real len = length(spring);
  spring -= dot(spring, n) * n;
  real projected = length(spring);
  if (projected > 0.0) spring *= len / projected;
  spring += vs * dt;
  real k_t = 8.0 * real(c.extra.y) * sqrt(effective_radius * delta);  // [N/m]
  real gamma_s = real(c.coefficients.z);
  real3 force = -k_t * spring - gamma_s * vs;
  real cap = real(c.coefficients.y) * normal_force;
  real magnitude = length(force);
  if (magnitude > cap) {
    force *= magnitude > 0.0 ? cap / magnitude : real(0.0);
    spring = -(force + gamma_s * vs) / k_t;
  }
  return force;
}

// The spring form of the contact force (normal + tangential on sphere 1); advances `spring`.
real3 hertz_spring_contact_force(real3 n, real delta, real3 vc, real effective_radius, real effective_mass, SimPair c,
                                 int damping_model, real dt, inout real3 spring) {
  real normal = hertz_normal_force(n, delta, vc, effective_radius, effective_mass, c, damping_model);
  return normal * n + spring_tangential_force(n, delta, vc, effective_radius, normal, c, dt, spring);
}
#endif
