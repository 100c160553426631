#include "sim/contact_model.h"

#include <cassert>
#include <cmath>
#include <map>
#include <mutex>
#include <utility>

namespace ts::sim {

std::string validate(const Material& m) {
  if (!(m.youngs_modulus > 0) || !std::isfinite(m.youngs_modulus)) return "E: must be > 0 (Pa)";
  if (!(m.poisson_ratio >= 0 && m.poisson_ratio < 0.5)) return "nu: must be in [0, 0.5)";
  if (!(m.restitution >= 0.05 && m.restitution <= 1)) return "restitution: must be in [0.05, 1]";
  if (!(m.friction >= 0) || !std::isfinite(m.friction)) return "mu: must be >= 0";
  if (!(m.tangential_damping >= 0) || !std::isfinite(m.tangential_damping)) return "gamma_s: must be >= 0 (N s/m)";
  if (!(m.density > 0) || !std::isfinite(m.density)) return "density: must be > 0 (kg/m^3)";
  return {};
}

namespace {

// Right-hand side of the scaled oscillator: acceleration for overlap x and rate u.
double scaled_acceleration(double x, double u, double strength, double exponent) {
  if (x <= 0) return 0;
  const double force = x * std::sqrt(x) + strength * std::pow(x, exponent) * u;
  return -std::max(0.0, force);
}

}  // namespace

ScaledImpact scaled_hertz_impact(double strength, double exponent) {
  // The undamped contact lasts 3.2145 time units; 1000 RK4 steps per unit resolve the x^p start
  // well enough for 1e-4 in the restitution.
  constexpr double h = 1.0 / 1000.0;
  double x = 0, u = 1, t = 0;
  while (t < 100.0) {
    const double a1 = scaled_acceleration(x, u, strength, exponent);
    const double x2 = x + 0.5 * h * u, u2 = u + 0.5 * h * a1;
    const double a2 = scaled_acceleration(x2, u2, strength, exponent);
    const double x3 = x + 0.5 * h * u2, u3 = u + 0.5 * h * a2;
    const double a3 = scaled_acceleration(x3, u3, strength, exponent);
    const double x4 = x + h * u3, u4 = u + h * a3;
    const double a4 = scaled_acceleration(x4, u4, strength, exponent);
    const double x_next = x + h / 6 * (u + 2 * u2 + 2 * u3 + u4);
    const double u_next = u + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    if (x_next <= 0 && t > 0) {
      // Interpolate the crossing of x = 0 linearly within the step.
      const double fraction = x / (x - x_next);
      return {-(u + fraction * (u_next - u)), t + fraction * h};
    }
    x = x_next;
    u = u_next;
    t += h;
  }
  return {0.0, t};  // stuck: overdamped
}

double damping_strength_for_restitution(double restitution, double exponent) {
  assert(restitution > 0 && restitution <= 1);
  if (restitution >= 1) return 0;
  // Scenes reuse a handful of (e, p) pairs: remember them.
  static std::mutex mutex;
  static std::map<std::pair<double, double>, double> known;
  const std::lock_guard lock(mutex);
  if (const auto it = known.find({restitution, exponent}); it != known.end()) return it->second;
  double low = 0, high = 1;
  while (scaled_hertz_impact(high, exponent).restitution > restitution) high *= 2;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (low + high);
    (scaled_hertz_impact(mid, exponent).restitution > restitution ? low : high) = mid;
  }
  return known[{restitution, exponent}] = 0.5 * (low + high);
}

PairCoefficients make_pair_coefficients(const Material& a, const Material& b, NormalDamping damping,
                                        double thesis_reference_speed) {
  PairCoefficients p;
  p.effective_modulus = 1.0 / ((1 - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus +
                               (1 - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus);
  // Geometric means, as LAMMPS's pair granular mixes unlike coefficients.
  p.friction = std::sqrt(a.friction * b.friction);
  p.tangential_damping = std::sqrt(a.tangential_damping * b.tangential_damping);
  p.restitution = std::sqrt(a.restitution * b.restitution);
  const double exponent = damping == NormalDamping::Tsuji ? 0.25 : 0.5;
  p.damping_strength = damping_strength_for_restitution(p.restitution, exponent);
  p.thesis_reference_speed = thesis_reference_speed;
  const double g_a = a.youngs_modulus / (2 * (1 + a.poisson_ratio)), g_b = b.youngs_modulus / (2 * (1 + b.poisson_ratio));
  p.effective_shear_modulus = 1.0 / ((2 - a.poisson_ratio) / g_a + (2 - b.poisson_ratio) / g_b);
  return p;
}

}  // namespace ts::sim
