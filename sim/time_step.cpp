#include "sim/time_step.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace ts::sim {

double hertz_contact_duration(double effective_mass, double effective_radius, double effective_modulus,
                              double impact_speed) {
  const double k_n = 4.0 / 3.0 * effective_modulus * std::sqrt(effective_radius);  // N/m^1.5
  return 3.21 * std::pow(effective_mass / k_n, 0.4) * std::pow(impact_speed, -0.2);
}

double rayleigh_time(double radius, const Material& m) {
  const double shear_modulus = m.youngs_modulus / (2 * (1 + m.poisson_ratio));  // Pa
  return std::numbers::pi * radius * std::sqrt(m.density / shear_modulus) / (0.1631 * m.poisson_ratio + 0.8766);
}

double grain_tangential_inverse_mass(const GrainShape& g) {
  const double arm = g.centre_distance + g.particle_radius;  // m
  return 1.0 / g.mass + arm * arm / g.inertia;
}

TimeStepBound time_step_bound(const std::vector<ContactCase>& cases, const std::vector<ParticleKind>& particles,
                              double max_impact_speed) {
  TimeStepBound b;
  b.max_impact_speed = max_impact_speed;
  b.contact_duration = std::numeric_limits<double>::infinity();
  b.rayleigh = std::numeric_limits<double>::infinity();
  b.tangential = std::numeric_limits<double>::infinity();
  for (const ContactCase& c : cases) {
    if (c.tangential_mass > 0 && c.tangential_damping > 0) {
      b.tangential = std::min(b.tangential, c.tangential_mass / c.tangential_damping);
    }
    b.contact_duration = std::min(
        b.contact_duration,
        hertz_contact_duration(c.effective_mass, c.effective_radius, c.effective_modulus, max_impact_speed));
  }
  for (const ParticleKind& p : particles) b.rayleigh = std::min(b.rayleigh, rayleigh_time(p.radius, p.material));
  b.recommended = std::min({b.contact_duration / 20, 0.2 * b.rayleigh, b.tangential});
  return b;
}

void add_bond_bound(TimeStepBound& bound, double bond_step) {
  bound.bonds = bond_step;
  bound.recommended = std::min(bound.recommended, bond_step);
}

std::string limiting_bound(const TimeStepBound& b) {
  if (b.recommended == b.contact_duration / 20) return "t_c/20";
  if (b.recommended == 0.2 * b.rayleigh) return "0.2 t_R";
  if (b.recommended == b.tangential) return "m_t/gamma_s";
  return "bonds";
}

std::string check_time_step(double dt, const TimeStepBound& b) {
  if (dt <= b.recommended) return {};
  const std::string bonds = std::isfinite(b.bonds) ? fmt::format(", bonds {:.3g} s", b.bonds) : "";
  return fmt::format("dt = {:.3g} s exceeds the stable bound {:.3g} s (t_c/20 = {:.3g} s at {:.3g} m/s impacts, "
                     "0.2 t_R = {:.3g} s, m_t/gamma_s = {:.3g} s{})",
                     dt, b.recommended, b.contact_duration / 20, b.max_impact_speed, 0.2 * b.rayleigh, b.tangential,
                     bonds);
}

}  // namespace ts::sim
