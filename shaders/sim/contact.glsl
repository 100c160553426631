// The contact model (thesis chapter 3; shared/notes/formulas.md), line for line the GLSL twin of
// sim/contact_model.h (hertz_contact_force, sphere_sphere_contact, sphere_wall_contact), so the GPU
// and the CPU reference agree to float rounding. All of it is in `creal` (sim/precision.glsl): float,
// but for the full-double comparison pipeline. The force acts on sphere 1 at the middle of the
// overlap, the same point for both partners, so every pair conserves angular momentum.
#ifndef TETRASAND_SIM_CONTACT_GLSL
#define TETRASAND_SIM_CONTACT_GLSL
#include "common/layouts.h"
#include "sim/precision.glsl"

#define TS_DAMPING_TSUJI 0
#define TS_DAMPING_THESIS 1

// The normal force magnitude [N]: Hertz (eq. 3.19) plus damping, never attractive.
// n: unit normal towards sphere 1; delta: overlap [m] > 0; vc: contact velocity of 1 relative to 2.
creal hertz_normal_force(creal3 n, creal delta, creal3 vc, creal effective_radius, creal effective_mass, SimPair c,
                         int damping_model) {
  creal e_star = creal(c.coefficients.x);
  creal k_n = 4.0 / 3.0 * e_star * sqrt(effective_radius);  // eq. 3.19 [N/m^1.5]
  creal delta_dot = -dot(vc, n);                             // > 0 while approaching [m/s]
  creal damping;
  if (damping_model == TS_DAMPING_TSUJI) {
    creal s_n = 2.0 * e_star * sqrt(effective_radius * delta);
    damping = creal(2.0 * sqrt(5.0 / 6.0) / sqrt(5.0)) * creal(c.coefficients.w) * sqrt(s_n * effective_mass) * delta_dot;
  } else {
    // Thesis eq. 3.27 with gamma_n = c (m*^2 k_n^3 / v_ref)^(1/5); pow has no double overload.
    creal gamma_n = creal(c.coefficients.w) *
                    creal(pow(float(effective_mass * effective_mass * k_n * k_n * k_n / creal(c.extra.x)), 0.2));
    damping = gamma_n * sqrt(delta) * delta_dot;
  }
  return max(creal(0.0), k_n * delta * sqrt(delta) + damping);  // contacts push, never pull
}

// Eq. 3.28: viscous slip force capped by Coulomb (normal + tangential force on sphere 1).
creal3 hertz_contact_force(creal3 n, creal delta, creal3 vc, creal effective_radius, creal effective_mass, SimPair c,
                           int damping_model) {
  creal normal = hertz_normal_force(n, delta, vc, effective_radius, effective_mass, c, damping_model);
  creal3 vs = vc - dot(vc, n) * n;
  creal slip = length(vs);
  creal3 tangential = creal3(0.0);
  if (slip > 0.0) tangential = -(min(creal(c.coefficients.y) * normal, creal(c.coefficients.z) * slip) / slip) * vs;
  return normal * n + tangential;
}

// Static friction (sim::spring_tangential_force): the contact's elastic tangential displacement
// `spring` [m] is turned onto the tangent plane keeping its length, advanced by the slip over dt [s],
// and the force -k_t spring - gamma_s v_s, k_t = 8 G* sqrt(R* delta), is capped at mu F_n; while
// sliding, the spring is cut back to what the capped force implies. The spring is state carried from
// step to step, so it stays in `real` (double in the double pipelines): in float, sticking contacts
// would add one rounding per step to it. Its length is kept by adding the small correction
// spring * (sqrt(1 + a^2 / p^2) - 1) (a: the part along n, p: the projected length), which float
// resolves to a rounding of the correction, not of the spring.
creal3 spring_tangential_force(creal3 n, creal delta, creal3 vc, creal effective_radius, creal normal_force, SimPair c,
                               real dt, inout real3 spring) {
  creal3 vs = vc - dot(vc, n) * n;
  real along = dot(spring, real3(n));
  spring -= along * real3(n);
  creal3 projected = creal3(spring);
  creal p2 = dot(projected, projected);
  if (p2 > 0.0) {
    creal r = creal(along) * creal(along) / p2;
    spring += spring * real(r / (sqrt(1.0 + r) + 1.0));  // = spring * (len / projected - 1)
  }
  spring += real3(vs) * dt;
  creal k_t = 8.0 * creal(c.extra.y) * sqrt(effective_radius * delta);  // [N/m]
  creal gamma_s = creal(c.coefficients.z);
  creal3 force = -k_t * creal3(spring) - gamma_s * vs;
  creal cap = creal(c.coefficients.y) * normal_force;
  creal magnitude = length(force);
  if (magnitude > cap) {
    // force *= scale, and spring = -(force + gamma_s v_s) / k_t written as spring * scale plus a
    // float correction: the float force would round the spring, this keeps its `real` digits.
    creal scale = magnitude > 0.0 ? cap / magnitude : creal(0.0);
    force *= scale;
    spring = spring * real(scale) + real3((scale - 1.0) * gamma_s / k_t * vs);
  }
  return force;
}

// The spring form of the contact force (normal + tangential on sphere 1); advances `spring`.
creal3 hertz_spring_contact_force(creal3 n, creal delta, creal3 vc, creal effective_radius, creal effective_mass, SimPair c,
                                  int damping_model, real dt, inout real3 spring) {
  creal normal = hertz_normal_force(n, delta, vc, effective_radius, effective_mass, c, damping_model);
  return normal * n + spring_tangential_force(n, delta, vc, effective_radius, normal, c, dt, spring);
}
#endif
