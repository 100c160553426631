// Criteria 3 and 4 of docs/validation.md "Bonded particles" on the CPU reference, on bonded FCC
// cylinders built directly as Worlds (neighbours touching without overlap).
//
// Criterion 3 (elastic stiffness): the apparent Young's modulus E_app from a static uniaxial compression,
// then the static tip deflection of a cantilever of the same packing under a small end load against
// Euler-Bernoulli with that E_app (criterion: within 15 %). Both loads are static: the end load is a
// constant force added to the loaded spheres' velocities each step (F dt / m, as the stepper adds its
// own forces), and every dynamic sphere's linear and angular velocity is damped by (1 - c dt) after
// each step, c twice the specimen's lowest angular frequency (critical for that mode; every faster mode
// then decays at the same rate c / 2). The damping is the test driver's, not the model's. Under a
// steady load the cantilever keeps creeping slowly against the load at a rate proportional to dt (a
// finding, docs/validation.md), so the static value is read from a straight line fitted after the
// transient, at the load's start (settle()). The time step is a few times the bonds' own bound
// (bond_time_step, which keeps motions accurate), and the runs are repeated at smaller steps.
//
// The stiffness runs take minutes (criterion 3 is met on the 10-across cylinder, not on the 5-across
// one), so they are DISABLED_ (run them with --gtest_also_run_disabled_tests); the strength test of
// criterion 4 at the end runs in CI.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "sim/cpu_bonds.h"
#include "sim/cpu_stepper.h"

namespace ts::sim {
namespace {

using V = Eigen::Vector3d;
constexpr double kRadius = 1e-3;          // m
constexpr double kBondModulus = 1e8;      // Pa, E of the bond cement
const double kCell = 4.0 * std::sqrt(2.0) * std::pow(kRadius, 3);  // m^3, FCC volume per sphere
const double kPlaneSpacing = std::sqrt(2.0) * kRadius;           // m, between FCC planes normal to x

// A bonded FCC cylinder along x: `across` spheres across its diameter (D = 2 r across), `planes`
// lattice planes long. Spheres of the first two planes are static (the clamp); the rest dynamic.
struct Specimen {
  World world;
  std::vector<std::uint32_t> loaded;          // bodies of the last plane (where the end load acts)
  std::vector<std::vector<std::uint32_t>> plane;  // bodies by plane index
  double length = 0;       // m, from the last clamped plane to the loaded plane
  double area = 0;         // m^2, the section's: sphere count x cell volume / specimen length
  double second_moment = 0;  // m^4, about the section's centroid for bending in y (same measure)
  double density = 0;      // kg/m^3
  double dt = 0;           // s
};

BondMaterial unbreakable() {
  BondMaterial bond;
  bond.youngs_modulus = kBondModulus;
  bond.tensile_strength = 1e12;  // nothing breaks: only the elastic response is measured
  bond.shear_strength = 1e12;
  return bond;
}

Specimen bonded_cylinder(int across, int planes, double step_factor, const BondMaterial& bond = unbreakable(),
                         std::uint64_t seed = 7) {
  Specimen s;
  World& w = s.world;
  w.materials.push_back(Material{});
  w.gravity = V::Zero();
  const double half = kPlaneSpacing;  // half the cube edge 2 sqrt(2) r
  const double reach = (across - 1) * kRadius;  // largest centre distance from the axis (D/2 - r)
  const int lateral = across + 2;
  std::vector<V> centres;
  std::vector<int> plane_of;
  for (int i = 0; i < planes; ++i)
    for (int j = -lateral; j <= lateral; ++j)
      for (int k = -lateral; k <= lateral; ++k) {
        if ((i + j + k) % 2 != 0) continue;  // FCC: the sites of a cubic grid of spacing half whose indices sum to even
        const V c(i * half, j * half, k * half);
        if (std::hypot(c.y(), c.z()) > reach + 1e-12) continue;
        centres.push_back(c);
        plane_of.push_back(i);
      }
  s.density = w.materials[0].density;
  const double mass = s.density * kCell;
  s.plane.resize(static_cast<std::size_t>(planes));
  double sum_y = 0;
  for (const V& c : centres) sum_y += c.y();
  const double mean_y = sum_y / static_cast<double>(centres.size());
  double moment = 0;
  const double cell_edge = std::cbrt(kCell);
  for (std::size_t n = 0; n < centres.size(); ++n) {
    BodyDesc d;
    d.position = centres[n];
    if (plane_of[n] < 2) {
      d.motion = MotionType::Static;
    } else {
      d.inverse_mass = 1.0 / mass;
      d.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * mass * kRadius * kRadius);
    }
    const std::uint32_t id = add_body(w, d, {V::Zero()}, {kRadius}, 0);
    s.plane[static_cast<std::size_t>(plane_of[n])].push_back(id);
    if (plane_of[n] == planes - 1) s.loaded.push_back(id);
    // each sphere stands for its lattice cell: its centre's arm plus the cell's own moment
    moment += kCell * (std::pow(centres[n].y() - mean_y, 2) + cell_edge * cell_edge / 12.0);
  }
  const double specimen_length = planes * kPlaneSpacing;
  s.area = static_cast<double>(centres.size()) * kCell / specimen_length;
  s.second_moment = moment / specimen_length;
  s.length = (planes - 2) * kPlaneSpacing;
  w.bonds = build_bonds(centres, std::vector<double>(centres.size(), kRadius), bond, seed);
  w.bond_materials = {bond};
  const std::vector<double> masses(centres.size(), mass);
  s.dt = step_factor * bond_time_step(w.bonds, masses, w.particles.radius, bond);
  return s;
}

double mean_displacement(const World& w, const std::vector<std::uint32_t>& bodies, const std::vector<V>& start,
                         const V& direction) {
  double sum = 0;
  for (std::uint32_t k : bodies) sum += (w.bodies.position[k] - start[k]).dot(direction);
  return sum / static_cast<double>(bodies.size());
}

// What a static load gives: the read displacement (m) with the start transient decayed, and the slow
// creep seen under a steady load (m/s; docs/validation.md criterion 3 finding: it shrinks with dt).
struct Settled {
  double displacement = 0;  // the late straight line's value at the load's start
  double creep = 0;         // its slope
};

// Applies `force` (N, shared evenly by the loaded spheres) with the driver's damping for 2 kWindows
// windows of 1 / c: the transient decays by exp(-kWindows / 2) over the first kWindows, and the second
// kWindows are fitted with a straight line in time (least squares) whose value at the load's start is
// the static displacement without the creep.
constexpr int kWindows = 30;

template <typename Read>
Settled settle(Specimen& s, const V& force, double omega, const Read& read) {
  World& w = s.world;
  StepSettings settings;
  settings.dt = s.dt;
  settings.integrator = Integrator::SemiImplicitEuler;
  settings.design_speed = 0.01;
  settings.check_energy = false;  // the driver's load does work on the specimen
  CpuStepper stepper(w, settings);
  const double damping = 2.0 * omega;  // 1/s
  const double keep = 1.0 - damping * s.dt;
  const V kick = force / static_cast<double>(s.loaded.size()) * s.dt * w.bodies.inverse_mass[s.loaded[0]];
  const auto window = std::max<std::int64_t>(1, static_cast<std::int64_t>(1.0 / (damping * s.dt)));
  double st = 0, sx = 0, stt = 0, stx = 0;
  int fitted = 0;
  for (int round = 1; round <= 2 * kWindows; ++round) {
    for (std::int64_t step = 0; step < window; ++step) {
      stepper.step(w);
      for (std::size_t k = 0; k < w.bodies.size(); ++k) {
        w.bodies.linear_velocity[k] *= keep;
        w.bodies.angular_velocity[k] *= keep;
      }
      for (std::uint32_t k : s.loaded) w.bodies.linear_velocity[k] += kick;
    }
    const double now = read(w);
    if (round <= kWindows) continue;
    const double t = static_cast<double>(round * window) * s.dt;
    st += t, sx += now, stt += t * t, stx += t * now;
    ++fitted;
  }
  Settled out;
  out.creep = (fitted * stx - st * sx) / (fitted * stt - st * st);
  out.displacement = (sx - out.creep * st) / fitted;
  return out;
}

struct Stiffness {
  double apparent_modulus = 0;  // E_app, Pa
  double measured_tip = 0;      // m
  double predicted_tip = 0;     // m, P L^3 / (3 E_app I)
  double axial_creep = 0, tip_creep = 0;  // relative to the settled value, per second
  std::size_t spheres = 0, bonds = 0;
};

Stiffness measure(int across, int planes, double step_factor) {
  Stiffness out;
  const Specimen fresh = bonded_cylinder(across, planes, step_factor);
  out.spheres = fresh.world.bodies.size();
  out.bonds = fresh.world.bonds.size();
  const std::vector<V> start = fresh.world.bodies.position;

  // Compression: the strain read between the planes at a quarter and three quarters of the length
  // (away from the clamp's and the load's local disturbance).
  Specimen axial = fresh;
  const double strain_target = 1e-5;
  const double push = strain_target * kBondModulus * axial.area;  // N, about that strain if E_app ~ E
  const auto quarter = static_cast<std::size_t>(2 + (planes - 2) / 4);
  const auto three_quarters = static_cast<std::size_t>(2 + 3 * (planes - 2) / 4);
  const double gauge = static_cast<double>(three_quarters - quarter) * kPlaneSpacing;
  const double wave = std::sqrt(kBondModulus / axial.density);
  const auto shortening = [&](const World& w) {
    return mean_displacement(w, axial.plane[quarter], start, V::UnitX()) -
           mean_displacement(w, axial.plane[three_quarters], start, V::UnitX());
  };
  const Settled squeezed = settle(axial, V(-push, 0, 0), 0.5 * std::numbers::pi * wave / axial.length, shortening);
  out.apparent_modulus = (push / axial.area) / (squeezed.displacement / gauge);
  out.axial_creep = squeezed.creep / squeezed.displacement;

  // Cantilever: an end load in y, sized for a tip deflection of about 1e-4 of the length.
  Specimen beam = fresh;
  const double tip_target = 1e-4 * beam.length;
  const double load = 3.0 * out.apparent_modulus * beam.second_moment * tip_target / std::pow(beam.length, 3);
  const double omega = 3.516 * std::sqrt(out.apparent_modulus * beam.second_moment /
                                         (beam.density * beam.area * std::pow(beam.length, 4)));
  const auto tip = [&](const World& w) { return mean_displacement(w, beam.loaded, start, V::UnitY()); };
  const Settled bent = settle(beam, V(0, load, 0), omega, tip);
  out.measured_tip = bent.displacement;
  out.tip_creep = bent.creep / bent.displacement;
  out.predicted_tip = load * std::pow(beam.length, 3) / (3.0 * out.apparent_modulus * beam.second_moment);
  return out;
}

void report(const char* name, int across, int planes, double step_factor, const Stiffness& s) {
  std::printf("%s: %d spheres across, %d planes (L/D %.2f), %zu spheres, %zu bonds, dt %.2f x the bonds' bound: "
              "E_app/E = %.4f; tip %.4e m measured, %.4e m Euler-Bernoulli, ratio %.4f; creep under the load "
              "%.3g/s axial, %.3g/s tip (relative)\n",
              name, across, planes, (planes - 2) * kPlaneSpacing / (2.0 * across * kRadius), s.spheres, s.bonds,
              step_factor, s.apparent_modulus / kBondModulus, s.measured_tip, s.predicted_tip,
              s.measured_tip / s.predicted_tip, s.axial_creep, s.tip_creep);
}

// The small cylinder (5 spheres across, L/D about 4) at three steps, checked against the criterion at
// each (about two minutes). DISABLED_: criterion 3 is not met on a section this coarse
// (docs/validation.md, 2026-12-07: tip 1.17 to 1.19 times Euler-Bernoulli's), so it cannot stand as a
// CI test; run it with --gtest_also_run_disabled_tests.
TEST(BondStiffness, DISABLED_SmallCantileverBendsAsEulerBernoulliWithTheModulusFromCompression) {
  for (double factor : {5.0, 2.5, 1.0}) {
    const Stiffness s = measure(5, 30, factor);
    report("small bonded cylinder", 5, 30, factor, s);
    EXPECT_NEAR(s.measured_tip / s.predicted_tip, 1.0, 0.15) << "criterion 3: within 15 % of Euler-Bernoulli";
  }
}

// The small cylinder twice as slender (L/D about 8): how much of the gap to Euler-Bernoulli is the short
// beam's shear and the clamp's give, both of which fall with D / L (minutes).
TEST(BondStiffness, DISABLED_SlenderSmallCantileverBendsAsEulerBernoulli) {
  const Stiffness s = measure(5, 58, 5.0);
  report("slender small bonded cylinder", 5, 58, 5.0, s);
  EXPECT_NEAR(s.measured_tip / s.predicted_tip, 1.0, 0.15) << "criterion 3: within 15 % of Euler-Bernoulli";
}

// The criterion's specimen: about 10 spheres across a section, L/D about 4, at two steps (12 minutes on
// 2 shared cores).
TEST(BondStiffness, DISABLED_TenAcrossCantileverBendsAsEulerBernoulliWithTheModulusFromCompression) {
  const int across = 10, planes = 58;
  for (double factor : {5.0, 2.5}) {
    const Stiffness s = measure(across, planes, factor);
    report("bonded cylinder", across, planes, factor, s);
    EXPECT_NEAR(s.measured_tip / s.predicted_tip, 1.0, 0.15) << "criterion 3: within 15 % of Euler-Bernoulli";
  }
}

// Criterion 4 (strength): uniaxial tension of the same cylinder between two grips, the first and the
// last two planes moved apart as kinematic bodies. Loaded slowly: the whole specimen starts with the
// grips' straight velocity profile (no wave from a sudden start), and the stress would reach the
// bonds' tensile strength (at E_app ~ E) in kLoadingTransits times the time a wave takes along it.
// Peak stress: the largest pull the bonds across the far grip carry, over the section's area.
constexpr double kLoadingTransits = 20.0;

struct Pull {
  double peak_stress = 0;  // Pa
  std::size_t broken = 0, bonds = 0;
};

Pull pull_apart(int across, int planes, double spread, std::uint64_t seed) {
  BondMaterial bond = unbreakable();
  bond.tensile_strength = 1e5;  // Pa: failure near a strain of 1e-3, small rotations
  bond.shear_strength = 1e5;
  bond.strength_spread = spread;
  Specimen s = bonded_cylinder(across, planes, 1.0, bond, seed);
  World& w = s.world;
  const double length = (planes - 1) * kPlaneSpacing;
  const double wave = std::sqrt(kBondModulus / s.density);
  const double strain_rate = (bond.tensile_strength / kBondModulus) / (kLoadingTransits * length / wave);
  const double grip_speed = 0.5 * strain_rate * length;  // m/s, each grip
  std::vector<std::uint8_t> far_grip(w.bodies.size(), 0);
  for (std::size_t k = 0; k < w.bodies.size(); ++k) {
    const double x = w.bodies.position[k].x();
    w.bodies.linear_velocity[k] = V(strain_rate * (x - 0.5 * length), 0, 0);
    const bool near = x < 1.5 * kPlaneSpacing, far = x > length - 1.5 * kPlaneSpacing;
    if (!near && !far) continue;
    far_grip[k] = far ? 1 : 0;
    w.bodies.motion[k] = MotionType::Kinematic;
    w.bodies.inverse_mass[k] = 0;
    w.bodies.inverse_inertia[k].setZero();
    w.bodies.linear_velocity[k] = V(far ? grip_speed : -grip_speed, 0, 0);
  }
  StepSettings settings;
  settings.dt = s.dt;
  settings.integrator = Integrator::SemiImplicitEuler;
  settings.design_speed = 10 * grip_speed;
  CpuStepper stepper(w, settings);
  Pull out;
  out.bonds = w.bonds.size();
  const auto steps = static_cast<std::int64_t>(3.0 * kLoadingTransits * length / wave / s.dt);
  for (std::int64_t step = 0; step < steps; ++step) {
    out.broken += stepper.step(w).bonds_broken;
    double pull = 0;  // N, what the bonds hold the far grip back with
    for (std::size_t n = 0; n < w.bonds.size(); ++n) {
      const std::uint32_t a = w.bonds.a[n], b = w.bonds.b[n];
      if (!w.bonds.intact[n] || far_grip[a] == far_grip[b]) continue;
      const V along = (w.bodies.position[a] - w.bodies.position[b]).normalized();
      const V on_a = w.bonds.state[n].normal_force * along + w.bonds.state[n].shear_force;
      pull -= far_grip[a] ? on_a.x() : -on_a.x();
    }
    out.peak_stress = std::max(out.peak_stress, pull / s.area);
    if (pull < 0.5 * out.peak_stress * s.area && out.broken > 0) break;  // pulled through
  }
  out.peak_stress /= bond.tensile_strength;  // reported over the strength
  return out;
}

struct Spread {
  double mean = 0, deviation = 0;  // of peak stress / tensile strength over the seeds
};

Spread over_seeds(int across, int planes, double spread, int seeds) {
  std::vector<double> peaks;
  for (int seed = 1; seed <= seeds; ++seed) {
    const Pull p = pull_apart(across, planes, spread, static_cast<std::uint64_t>(seed));
    std::printf("tension, %d across, %d planes, spread %.1f, seed %d: peak stress / tensile strength %.4f, "
                "%zu of %zu bonds broken\n",
                across, planes, spread, seed, p.peak_stress, p.broken, p.bonds);
    peaks.push_back(p.peak_stress);
  }
  Spread out;
  for (double x : peaks) out.mean += x / static_cast<double>(peaks.size());
  for (double x : peaks) out.deviation += (x - out.mean) * (x - out.mean) / static_cast<double>(peaks.size() - 1);
  out.deviation = std::sqrt(out.deviation);
  std::printf("tension, %d across, spread %.1f: peak stress / tensile strength mean %.4f, standard deviation %.4f, "
              "coefficient of variation %.4f over %d seeds\n",
              across, spread, out.mean, out.deviation, out.deviation / out.mean, seeds);
  return out;
}

void check_strength_criterion(int across, int planes, int seeds) {
  const Spread even = over_seeds(across, planes, 0.0, seeds);
  const Spread spread = over_seeds(across, planes, 0.3, seeds);
  EXPECT_GT(even.mean, 0.0);
  EXPECT_LT(even.deviation / even.mean, 0.25) << "criterion 4: coefficient of variation below 25 %";
  EXPECT_LT(spread.deviation / spread.mean, 0.25) << "criterion 4: coefficient of variation below 25 %";
  EXPECT_GT(spread.deviation / spread.mean, even.deviation / even.mean) << "criterion 4: grows with strength_spread";
}

// In CI: a short 5-across cylinder, 3 seeds per spread.
TEST(BondStrength, TensionPeakVariesLittleOverSeedsAndMoreWithStrengthSpread) {
  check_strength_criterion(5, 16, 3);
}

// The criterion as written: 5 seeds per spread on the 5-across, L/D 4 cylinder (minutes).
TEST(BondStrength, DISABLED_TensionPeakOverFiveSeeds) { check_strength_criterion(5, 30, 5); }

}  // namespace
}  // namespace ts::sim
