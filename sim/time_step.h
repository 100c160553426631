#pragma once
// Time-step bounds for Hertz contacts (thesis 3.2.3; notes/formulas.md).
#include <limits>
#include <string>
#include <vector>

#include "sim/contact_model.h"
#include "sim/grain.h"

namespace ts::sim {

// Hertz elastic contact duration at normal impact speed v_n (eq. 3.22):
// t_c = 3.21 (m*/k_n)^(2/5) v_n^(-1/5), k_n = 4/3 E* sqrt(R*). Masses kg, radius m, modulus Pa,
// speed m/s; returns s.
double hertz_contact_duration(double effective_mass, double effective_radius, double effective_modulus,
                              double impact_speed);

// Rayleigh wave time across a sphere of radius r (m): t_R = pi r sqrt(rho/G) / (0.1631 nu + 0.8766),
// G = E / (2 (1 + nu)). Returns s.
double rayleigh_time(double radius, const Material& material);

// One kind of contact the scene will see (grain-grain, grain-wall, grain-prop...).
struct ContactCase {
  double effective_mass;     // m*, kg
  double effective_radius;   // R*, m
  double effective_modulus;  // E*, Pa
  // The viscous tangential force is explicit too: slip decays as (1 - gamma_s dt / m_t) per step,
  // so dt <= m_t / gamma_s keeps it from flipping sign every step (an oscillation the Coulomb cap
  // bounds but does not damp). m_t (kg) is the pair's effective mass for a tangential push at the
  // contact point, including rotation: 1/m_t = sum over partners of (1/m + arm^2 / I).
  double tangential_mass = 0;     // kg; 0: no tangential bound
  double tangential_damping = 0;  // gamma_s, N s/m
};

// One grain's share of 1/m_t (1/kg) for a push at its far end (arm R + r): 1/m + (R + r)^2 / I.
double grain_tangential_inverse_mass(const GrainShape& grain);

struct TimeStepBound {
  double contact_duration = 0;  // s: shortest t_c over the cases at max_impact_speed
  double rayleigh = 0;          // s: shortest t_R over the particle materials
  double tangential = 0;        // s: shortest m_t / gamma_s over the cases (inf without friction damping)
  double max_impact_speed = 0;  // m/s
  // s: the bonds' step (sim/bonds.h bond_time_step; +inf without bonds), joined by add_bond_bound
  double bonds = std::numeric_limits<double>::infinity();
  double recommended = 0;       // s: min(t_c / 20, 0.2 t_R, m_t / gamma_s, bonds)
};

// Joins the bonds' step (s) to the bound: recommended becomes the smaller of the two.
void add_bond_bound(TimeStepBound& bound, double bond_step);

// Which term sets `recommended`: "t_c/20", "0.2 t_R", "m_t/gamma_s" or "bonds" (the first of equals).
std::string limiting_bound(const TimeStepBound& bound);

// `particles`: radius (m) and material of each kind of particle in the scene (for t_R).
struct ParticleKind {
  double radius;
  Material material;
};
TimeStepBound time_step_bound(const std::vector<ContactCase>& cases, const std::vector<ParticleKind>& particles,
                              double max_impact_speed);

// How far a time step given by hand may exceed TimeStepBound::recommended before a run refuses it
// (scene key simulation.check_time_step = false turns the refusal into the warning below). Why 2: the
// tightest part of the bound, m_t/gamma_s, is half of explicit damping's stability limit 2 m_t/gamma_s,
// so 2x is where the tangential force starts to flip sign every step; t_c/20 and 0.2 t_R have more
// margin (symplectic Euler on the stiffest Hertz contact diverges near t_c/2). docs/reliability.md.
inline constexpr double kHandTimeStepFactor = 2.0;

// Empty when dt (s) respects the bound, else a warning naming dt and the bound, e.g.
// "dt = 1e-4 s exceeds the stable bound 2.3e-6 s (t_c/20 = ... at 10 m/s, 0.2 t_R = ...)".
std::string check_time_step(double dt, const TimeStepBound& bound);

}  // namespace ts::sim
