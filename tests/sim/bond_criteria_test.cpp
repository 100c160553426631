// Criteria 3 and 4 of docs/validation.md "Bonded particles" on the CPU reference, on bonded FCC
// cylinders built directly as Worlds (neighbours touching without overlap).
//
// Criterion 3 (elastic stiffness): the apparent Young's modulus E_app from a static uniaxial compression,
// then the static tip deflection of a cantilever of the same packing under a small end load against
// Euler-Bernoulli with that E_app (criterion: within 15 %). Both loads are static: the end load is a
// constant force added to the loaded spheres' velocities after each step (F dt / m), every dynamic
// sphere's linear and angular velocity is then damped by (1 - c dt), c twice the specimen's lowest
// angular frequency (critical for that mode). The damping is the test driver's, not the model's. Each
// velocity change the driver makes also moves the sphere by it times dt, as if it had been part of the
// step (change_velocity: the bond law counts velocities, so a change the positions never saw would
// load the bonds: the creep of docs/validation.md), and the load is added before the damping (so the
// damping scales the whole step's impulse, not only the bonds'). The specimen then comes to rest in a
// state that does not depend on dt or on c; the static value is the reading at the end.
//
// The criterion's specimen (10 across) takes minutes and the 5-across one does not meet it, so those
// runs are DISABLED_ (bench/bond_criteria.py runs them); CI checks that the loaded beam comes to rest at
// an answer independent of dt, and guards the 5-across result. The strength test of criterion 4 at the
// end runs in CI.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/atomic_file.h"
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

// `jitter` (a fraction of r, 0: the lattice) moves every sphere off its site by a seeded uniform amount
// along each axis before the bonds are made (each bond is made at rest in that pose): a random packing
// whose geometry, not only the bonds' strengths, changes with the seed.
Specimen bonded_cylinder(int across, int planes, double step_factor, const BondMaterial& bond = unbreakable(),
                         std::uint64_t seed = 7, double jitter = 0.0) {
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
  if (jitter > 0) {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> off(-jitter * kRadius, jitter * kRadius);
    for (V& c : centres) c += V(off(random), off(random), off(random));
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

// Off by default: with TETRASAND_BOND_CRITERIA_CSV set to a folder, the criteria tests write their
// series there (bench/bond_criteria.py plots them), each file atomically.
void write_series(const std::string& name, const std::string& header, const std::vector<std::vector<double>>& rows) {
  const char* folder = std::getenv("TETRASAND_BOND_CRITERIA_CSV");
  if (folder == nullptr || *folder == '\0') return;
  std::string text = header + "\n";
  for (const std::vector<double>& row : rows) {
    for (std::size_t k = 0; k < row.size(); ++k) text += fmt::format("{}{:.10g}", k == 0 ? "" : ",", row[k]);
    text += "\n";
  }
  std::filesystem::create_directories(folder);
  write_file_atomically(std::filesystem::path(folder) / name, text);
}

// What a static load gives: the reading at rest (m), the drift left at the end (m/s: a straight line
// fitted over the second half of the run; it was the creep of docs/validation.md criterion 3 before the
// driver moved the positions with its velocity changes), and the reading after each window (the plots).
struct Settled {
  double displacement = 0;  // the last reading
  double drift = 0;         // the slope of the straight line fitted over the second half
  std::vector<double> time, reading;  // s, m: after each window
};

// Changes body k's linear velocity by dv after a step and moves it by dv dt, as if dv had been part of
// that step's velocity update: symplectic Euler moves x by the velocity it stores, and the bond law is
// incremental in that velocity (-k A v dt), so a velocity change the positions never saw would be
// counted by the next step's bonds as a motion that did not happen. Angular velocities need no such
// move: no bond reads the orientation of a one-sphere body.
void change_velocity(World& w, std::uint32_t k, const V& dv, double dt) {
  w.bodies.linear_velocity[k] += dv;
  w.bodies.position[k] += dv * dt;
}

// Applies `force` (N, shared evenly by the loaded spheres) with the driver's damping for 2 windows
// windows of 1 / c (c is critical for the estimated lowest mode; a beam softer than the estimate is
// overdamped and its tip creeps up to rest more slowly: the 5-across tip is within 3e-5 of its final
// value after 40 windows); the reading at the end is the static displacement, and a straight line
// fitted over the second half gives the drift.
constexpr int kWindows = 30;

template <typename Read>
Settled settle(Specimen& s, const V& force, double omega, const Read& read, int windows) {
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
  std::vector<std::uint8_t> loaded(w.bodies.size(), 0);
  for (std::uint32_t k : s.loaded) loaded[k] = 1;
  const auto window = std::max<std::int64_t>(1, static_cast<std::int64_t>(1.0 / (damping * s.dt)));
  double st = 0, sx = 0, stt = 0, stx = 0;
  int fitted = 0;
  Settled out;
  for (int round = 1; round <= 2 * windows; ++round) {
    for (std::int64_t step = 0; step < window; ++step) {
      stepper.step(w);
      for (std::uint32_t k = 0; k < w.bodies.size(); ++k) {
        if (w.bodies.motion[k] != MotionType::Dynamic) continue;
        const V& v = w.bodies.linear_velocity[k];
        const V dv = keep * (v + (loaded[k] ? kick : V::Zero())) - v;  // the load first, then the damping
        change_velocity(w, k, dv, s.dt);
        w.bodies.angular_velocity[k] *= keep;
      }
    }
    const double now = read(w);
    const double t = static_cast<double>(round * window) * s.dt;
    out.time.push_back(t);
    out.reading.push_back(now);
    if (round <= windows) continue;
    st += t, sx += now, stt += t * t, stx += t * now;
    ++fitted;
  }
  out.drift = (fitted * stx - st * sx) / (fitted * stt - st * st);
  out.displacement = out.reading.back();
  return out;
}

// How much a reading moved over the last 5 windows, relative to its last value.
double last_change(const Settled& s) {
  return std::abs(s.reading.back() - s.reading[s.reading.size() - 6]) / std::abs(s.reading.back());
}

struct Stiffness {
  double apparent_modulus = 0;  // E_app, Pa
  double measured_tip = 0;      // m
  double predicted_tip = 0;     // m, P L^3 / (3 E_app I)
  double axial_drift = 0, tip_drift = 0;  // relative to the settled value, per second
  std::size_t spheres = 0, bonds = 0;
  double dt = 0;                             // s
  Settled axial, tip;                        // the two loads' histories
};

Stiffness measure(int across, int planes, double step_factor, int windows = kWindows) {
  Stiffness out;
  const Specimen fresh = bonded_cylinder(across, planes, step_factor);
  out.spheres = fresh.world.bodies.size();
  out.bonds = fresh.world.bonds.size();
  out.dt = fresh.dt;
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
  const double axial_omega = 0.5 * std::numbers::pi * wave / axial.length;
  const Settled squeezed = settle(axial, V(-push, 0, 0), axial_omega, shortening, windows);
  out.apparent_modulus = (push / axial.area) / (squeezed.displacement / gauge);
  out.axial_drift = squeezed.drift / squeezed.displacement;

  // Cantilever: an end load in y, sized for a tip deflection of about 1e-4 of the length.
  Specimen beam = fresh;
  const double tip_target = 1e-4 * beam.length;
  const double load = 3.0 * out.apparent_modulus * beam.second_moment * tip_target / std::pow(beam.length, 3);
  const double omega = 3.516 * std::sqrt(out.apparent_modulus * beam.second_moment /
                                         (beam.density * beam.area * std::pow(beam.length, 4)));
  const auto tip = [&](const World& w) { return mean_displacement(w, beam.loaded, start, V::UnitY()); };
  const Settled bent = settle(beam, V(0, load, 0), omega, tip, windows);
  out.measured_tip = bent.displacement;
  out.tip_drift = bent.drift / bent.displacement;
  out.predicted_tip = load * std::pow(beam.length, 3) / (3.0 * out.apparent_modulus * beam.second_moment);
  out.axial = squeezed;
  out.tip = bent;
  return out;
}

void report(const char* name, int across, int planes, double step_factor, const Stiffness& s) {
  std::printf("%s: %d spheres across, %d planes (L/D %.2f), %zu spheres, %zu bonds, dt %.2f x the bonds' bound: "
              "E_app/E = %.4f; tip %.4e m measured, %.4e m Euler-Bernoulli, ratio %.4f; drift over the second half "
              "%.3g/s axial, %.3g/s tip, change over the last 5 windows %.2g axial, %.2g tip (relative)\n",
              name, across, planes, (planes - 2) * kPlaneSpacing / (2.0 * across * kRadius), s.spheres, s.bonds,
              step_factor, s.apparent_modulus / kBondModulus, s.measured_tip, s.predicted_tip,
              s.measured_tip / s.predicted_tip, s.axial_drift, s.tip_drift, last_change(s.axial), last_change(s.tip));
  const std::string id = fmt::format("stiffness_{}x{}_dt{}", across, planes, step_factor);
  write_series(id + ".csv", "spheres_across,planes,dt_over_bound,dt_s,E_app_over_E,tip_measured_m,tip_euler_bernoulli_m,"
                            "tip_ratio,axial_drift_per_s,tip_drift_per_s",
               {{static_cast<double>(across), static_cast<double>(planes), step_factor, s.dt,
                 s.apparent_modulus / kBondModulus, s.measured_tip, s.predicted_tip, s.measured_tip / s.predicted_tip,
                 s.axial_drift, s.tip_drift}});
  std::vector<std::vector<double>> rows;
  for (std::size_t n = 0; n < s.tip.time.size(); ++n) {
    rows.push_back({s.axial.time[n], s.axial.reading[n], s.tip.time[n], s.tip.reading[n], s.predicted_tip});
  }
  write_series(id + "_history.csv", "axial_t_s,shortening_m,tip_t_s,tip_m,tip_euler_bernoulli_m", rows);
}

// In CI: a short cantilever (5 across, 16 planes) under its end load comes to rest, and at the same
// deflection and shortening at two time steps. Both failed with the driver that changed velocities
// without moving the positions and damped the load's kick less than the bonds' (docs/validation.md
// criterion 3, the creep: the tip walked back against the load at a rate proportional to dt, and the
// static answers moved by 1 to 3 % between 2 and 5 times the bound on this cylinder). Seconds.
TEST(BondStiffness, LoadedCantileverComesToRestAtADeflectionIndependentOfTheTimeStep) {
  const int across = 5, planes = 16, windows = kWindows;
  const Stiffness coarse = measure(across, planes, 5.0, windows);
  report("short bonded cylinder", across, planes, 5.0, coarse);
  const Stiffness fine = measure(across, planes, 2.0, windows);
  report("short bonded cylinder", across, planes, 2.0, fine);
  // At rest: over the last 5 windows (5 / c) the readings move by less than 1e-4 of themselves (the old
  // driver's tip moved back by 1 to 3 % in that time).
  for (const Stiffness* s : {&coarse, &fine}) {
    EXPECT_LT(last_change(s->tip), 1e-4) << "the loaded cantilever is not at rest";
    EXPECT_LT(last_change(s->axial), 1e-4) << "the compressed cylinder is not at rest";
  }
  EXPECT_NEAR(fine.measured_tip / coarse.measured_tip, 1.0, 1e-3) << "the static deflection depends on dt";
  EXPECT_NEAR(fine.apparent_modulus / coarse.apparent_modulus, 1.0, 1e-3) << "the static shortening depends on dt";
}

// In CI, a regression guard, not criterion 3: the 5-across cylinder (L/D about 4) at 5 times the bound
// keeps the static answers recorded for it after the driver's fix (docs/validation.md criterion 3,
// 2026-12-08: E_app / E 1.1361, tip 1.1967 times Euler-Bernoulli's; the criterion wants 1.15 at most
// and is met only at 10 across). 1 % either way: the rest state itself repeats to 1e-6, so only a change
// in the law, the lattice or the measure moves them that far. 20 windows instead of 30: the recorded
// history has the tip within 3e-5 of its final value after 40 windows. About 10 s.
TEST(BondStiffness, SmallCylinderKeepsItsRecordedModulusAndCantileverDeflection) {
  const Stiffness s = measure(5, 30, 5.0, 20);
  report("small bonded cylinder", 5, 30, 5.0, s);
  EXPECT_NEAR(s.apparent_modulus / kBondModulus, 1.1361, 0.01 * 1.1361);
  EXPECT_NEAR(s.measured_tip / s.predicted_tip, 1.1967, 0.01 * 1.1967);
}

// The small cylinder (5 spheres across, L/D about 4) at three steps, checked against the criterion at
// each (about two minutes). DISABLED_: criterion 3 is not met on a section this coarse
// (docs/validation.md: tip about 1.19 times Euler-Bernoulli's), so it cannot stand as a CI test; run it
// with --gtest_also_run_disabled_tests (bench/bond_criteria.py does).
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
constexpr std::int64_t kCurveEvery = 100;  // steps between the stress-strain curve's points

struct Pull {
  double peak_stress = 0;  // Pa
  std::size_t broken = 0, bonds = 0;
  std::vector<std::vector<double>> curve;  // grip strain, stress over the tensile strength (for the plots)
};

Pull pull_apart(int across, int planes, double spread, std::uint64_t seed, double jitter) {
  BondMaterial bond = unbreakable();
  bond.tensile_strength = 1e5;  // Pa: failure near a strain of 1e-3, small rotations
  bond.shear_strength = 1e5;
  bond.strength_spread = spread;
  Specimen s = bonded_cylinder(across, planes, 1.0, bond, seed, jitter);
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
    if (step % kCurveEvery == 0) {
      const double strain = 2.0 * grip_speed * static_cast<double>(step + 1) * s.dt / length;
      out.curve.push_back({strain, pull / s.area / bond.tensile_strength});
    }
    if (pull < 0.5 * out.peak_stress * s.area && out.broken > 0) break;  // pulled through
  }
  out.peak_stress /= bond.tensile_strength;  // reported over the strength
  return out;
}

struct Spread {
  double mean = 0, deviation = 0;  // of peak stress / tensile strength over the seeds
};

Spread over_seeds(int across, int planes, double spread, int seeds, double jitter) {
  const std::string packing = jitter > 0 ? fmt::format("_jitter{}", jitter) : "";
  std::vector<double> peaks;
  std::vector<std::vector<double>> summary;
  for (int seed = 1; seed <= seeds; ++seed) {
    const Pull p = pull_apart(across, planes, spread, static_cast<std::uint64_t>(seed), jitter);
    std::printf("tension, %d across, %d planes, jitter %.2f r, spread %.1f, seed %d: peak stress / tensile strength "
                "%.4f, %zu of %zu bonds broken\n",
                across, planes, jitter, spread, seed, p.peak_stress, p.broken, p.bonds);
    peaks.push_back(p.peak_stress);
    write_series(fmt::format("tension_{}x{}{}_spread{}_seed{}.csv", across, planes, packing, spread, seed),
                 "grip_strain,stress_over_tensile_strength", p.curve);
    summary.push_back({static_cast<double>(seed), p.peak_stress, static_cast<double>(p.broken),
                       static_cast<double>(p.bonds)});
  }
  write_series(fmt::format("tension_{}x{}{}_spread{}_peaks.csv", across, planes, packing, spread),
               "seed,peak_stress_over_tensile_strength,bonds_broken,bonds", summary);
  Spread out;
  for (double x : peaks) out.mean += x / static_cast<double>(peaks.size());
  for (double x : peaks) out.deviation += (x - out.mean) * (x - out.mean) / static_cast<double>(peaks.size() - 1);
  out.deviation = std::sqrt(out.deviation);
  std::printf("tension, %d across, jitter %.2f r, spread %.1f: peak stress / tensile strength mean %.4f, standard "
              "deviation %.4f, coefficient of variation %.4f over %d seeds\n",
              across, jitter, spread, out.mean, out.deviation, out.deviation / out.mean, seeds);
  return out;
}

void check_strength_criterion(int across, int planes, int seeds, double jitter = 0.0) {
  const Spread even = over_seeds(across, planes, 0.0, seeds, jitter);
  const Spread spread = over_seeds(across, planes, 0.3, seeds, jitter);
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

// The same on a random packing (docs/validation.md criterion 4, on a jittered packing): every sphere
// moved off its site by up to 0.1 r along each axis, so at spread 0 the seeds give different packings
// (minutes).
TEST(BondStrength, DISABLED_TensionPeakOverFiveSeedsOnAJitteredPacking) { check_strength_criterion(5, 30, 5, 0.1); }

}  // namespace
}  // namespace ts::sim
