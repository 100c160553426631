// Bulk granular behaviour of the model (issue 6 "Physics tests"): a poured pile stands at an angle of
// repose that rises with friction and stays at rest once settled; a silo drains at a constant rate.
// Scenes are scaled for a 2-core CI machine: 5 mm spheres (grain bounding diameter 22 mm) and a soft
// E = 1 MPa keep the automatic time step near 0.2 ms, so a second of sand costs a few thousand steps
// on the CPU reference. Overlaps stay below 0.1 r at these loads (checked), so the soft modulus
// changes packing by a few per cent, not the behaviour under test.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/atomic_file.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "sim/cpu_stepper.h"
#include "scene/scene_world.h"
#include "tests/test_support.h"

namespace ts::sim {
using namespace ts::scene;  // these tests run whole scenes through the engine
namespace {

constexpr double kRadius = 5e-3;  // m, grain sphere radius used by these scenes
constexpr double kGammaS = 2.0;   // N s/m

std::string materials(double mu) {
  return fmt::format(R"(
[[material]]
name = "sand"
E = 1.0e6
nu = 0.3
restitution = 0.5
mu = {}
gamma_s = {}
density = 2600.0

[grain]
radius = {}
material = "sand"
)",
                     mu, kGammaS, kRadius);
}

// Grains poured from a small box 5-22 cm above a rough floor of fixed 5 mm spheres: the shared coarse
// pile of assets/scenes/reference/coarse_pile.toml (bench/sim_spring_creep.py pours the same one).
Scene pile_scene(double mu, std::size_t count, double duration,
                 TangentialModel tangential = TangentialModel::Viscous) {
  const std::filesystem::path file = test::asset("scenes/reference/coarse_pile.toml");
  Scene scene = parse_scene(read_file(file), file.string());
  EXPECT_EQ(scene.grains.at(0).radius, kRadius);
  scene.materials.at(0).friction = mu;
  scene.emitters.at(0).count = count;
  scene.simulation.duration = duration;
  scene.simulation.step.tangential = tangential;
  return scene;
}

struct Snapshot {
  World world;
  StepStats stats;
};

// Runs `scene` on the CPU reference and returns the final state.
Snapshot run_to_end(const Scene& scene) {
  Snapshot out;
  RunHooks hooks;
  hooks.on_output = [&](const World& w, const StepStats& s, std::int64_t) {
    out.world = w;
    out.stats = s;
  };
  run_scene(scene, test::temp_dir(), hooks);
  return out;
}

std::vector<std::size_t> grains_of(const World& w) {
  std::vector<std::size_t> out;
  for (std::size_t b = 0; b < w.bodies.size(); ++b)
    if (w.bodies.motion[b] == MotionType::Dynamic) out.push_back(b);
  return out;
}

// The angle of repose (degrees) of a heap on the plane z = 0: the grains' tops (z + bounding radius)
// binned by horizontal distance from the heap's axis (its centroid), the highest top per bin, and
// a least-squares line through the bins of the flank (from one bin off the axis out to where the
// heap is still two grains deep), angle = atan(-slope).
double angle_of_repose(const World& w, double bound) {
  const auto grains = grains_of(w);
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();
  for (std::size_t b : grains) axis += w.bodies.position[b].head<2>();
  axis /= static_cast<double>(grains.size());
  const double bin = 2 * bound;  // m
  std::vector<double> top(64, 0.0);
  for (std::size_t b : grains) {
    const auto k = static_cast<std::size_t>((w.bodies.position[b].head<2>() - axis).norm() / bin);
    if (k < top.size()) top[k] = std::max(top[k], w.bodies.position[b].z() + bound);
  }
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (std::size_t k = 1; k < top.size() && top[k] > 2 * bound; ++k) {
    const double x = (k + 0.5) * bin;
    sx += x;
    sy += top[k];
    sxx += x * x;
    sxy += x * top[k];
    n += 1;
  }
  if (n < 3) return 0.0;
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return std::atan(-slope) * 180.0 / std::numbers::pi;
}

double bounding_radius() { return make_tetrahedral_grain(kRadius, 2 * kRadius, 2600).bounding_radius; }

// Thesis 7.3: the angle of repose rises with inter-grain friction. The documented range for mu = 0.5
// on a rough floor is 15-30 degrees for this small (300-grain, about 3 grains tall) heap; measured
// 19.5 degrees, and 8.3 degrees at mu = 0.1 (viscous friction, thesis eq. 3.28).
TEST(GranularPhysics, PouredPileAngleOfReposeRisesWithFriction) {
  std::vector<double> angles;
  for (double mu : {0.1, 0.5}) {
    const Snapshot pile = run_to_end(pile_scene(mu, 300, 1.6));
    ASSERT_EQ(grains_of(pile.world).size(), 300u);
    EXPECT_LT(pile.stats.max_overlap_ratio, 0.1) << mu;
    angles.push_back(angle_of_repose(pile.world, bounding_radius()));
  }
  EXPECT_GT(angles[1], 15.0);
  EXPECT_LT(angles[1], 30.0);
  EXPECT_GT(angles[1], angles[0] + 5.0) << angles[0] << " deg at mu = 0.1, " << angles[1] << " deg at mu = 0.5";
}

// How far grains of a settled heap move (in sphere radii) over `seconds` more: the largest and the
// mean displacement of the grains' centres.
struct Creep {
  double largest = 0, mean = 0, angle_before = 0, angle_after = 0;
};
Creep creep_of_settled_pile(TangentialModel tangential, double seconds,
                            Integrator integrator = Integrator::ForwardEuler) {
  Scene scene = pile_scene(0.5, 300, 1.6, tangential);
  scene.simulation.step.integrator = integrator;
  World w = run_to_end(scene).world;
  const World settled = w;
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, w, nullptr);
  CpuStepper stepper(w, settings);
  while (w.time < settled.time + seconds) stepper.step(w);
  Creep c;
  const auto grains = grains_of(w);
  for (std::size_t b : grains) {
    const double d = (w.bodies.position[b] - settled.bodies.position[b]).norm() / kRadius;
    c.largest = std::max(c.largest, d);
    c.mean += d / static_cast<double>(grains.size());
  }
  c.angle_before = angle_of_repose(settled, bounding_radius());
  c.angle_after = angle_of_repose(w, bounding_radius());
  return c;
}

// Thesis figure 2.8: a heap at rest must stay at rest. With the tangential spring (static friction)
// the settled pile's grains move less than 2 % of a radius on average over a further second, and the
// slope keeps its angle. (The thesis's viscous friction, eq. 3.28, cannot: measured on this pile,
// the grains creep 0.4 radii per second and the slope falls from 19.5 to 16 degrees in a second.)
// Symplectic Euler: forward Euler gains energy in every oscillation of the undamped tangential spring
// as it does in the normal one, and the pile it pours is a pancake (6.3 degrees measured, against
// 14.7 with symplectic Euler on the same pour; the run warns about that pairing).
TEST(GranularPhysics, SettledPileWithStaticFrictionStaysAtRest) {
  const Creep c = creep_of_settled_pile(TangentialModel::Spring, 1.0, Integrator::SemiImplicitEuler);
  EXPECT_LT(c.mean, 0.02);
  EXPECT_LT(c.largest, 0.5);
  EXPECT_NEAR(c.angle_after, c.angle_before, 0.5);
  // A heap, not a pancake. Still flatter than the viscous heap (19.5 degrees forward, 22.6 symplectic
  // measured on this pour): LAMMPS's `tangential mindlin` pours the same flat heap; the cause is the cap
  // rule both share (docs/validation.md, "Spring heap against LAMMPS").
  EXPECT_GT(c.angle_before, 10.0);
}

// A flat-bottomed slot silo (quasi-2D, 3 volume-equivalent grain diameters d thick): 20 cm (12.5 d)
// wide between smooth walls, its floor two rough plates either side of an 8 cm (5 d) slot, above
// Beverloo's free-flow limit and 2.5 times narrower than the silo, closed by a third plate, the gate.
// A slot keeps the settled column (370 grains, 16 cm) taller than the orifice with few grains.
Scene silo_scene(std::size_t count) {
  const std::string text = materials(0.5) + fmt::format(R"(
[[emitter]]
type = "fill"
min = [-0.1, -0.025, 0.002]
max = [0.1, 0.025, 0.7]
count = {}
seed = 5

[[boundary]]
type = "plane"
point = [-0.1, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
material = "sand"

[[boundary]]
type = "plane"
point = [0.1, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
material = "sand"

[[boundary]]
type = "plane"
point = [0.0, -0.025, 0.0]
normal = [0.0, 1.0, 0.0]
material = "sand"

[[boundary]]
type = "plane"
point = [0.0, 0.025, 0.0]
normal = [0.0, -1.0, 0.0]
material = "sand"

[[boundary]]
type = "plane"
rough = true
point = [-0.07, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
size = [0.06, 0.05]
particle_radius = 5.0e-3
material = "sand"

[[boundary]]
type = "plane"
rough = true
point = [0.07, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
size = [0.06, 0.05]
particle_radius = 5.0e-3
material = "sand"

[[boundary]]            # the gate
type = "plane"
rough = true
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
size = [0.08, 0.05]
particle_radius = 5.0e-3
material = "sand"
)",
                                                        count);
  Scene scene = parse_scene(text, "silo.toml");
  scene.simulation.max_impact_speed = 1.0;  // m/s: the settled column's, not the first landing's
  return scene;
}

struct LineFit {
  double slope = 0, r_squared = 0;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / n, my += y[i] / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  return {sxy / sxx, sxy * sxy / (sxx * syy)};
}

// The mass out of the silo (grains below the floor, kg) against the time since its gate opened (s),
// sampled every 50 steps from the opening until 80 % of the grains are out or 1.5 s have passed: one
// fill of silo_scene, its fill emitter seeded with `seed`.
struct Discharge {
  std::vector<double> time, mass;
};

Discharge discharge_of_fill(std::size_t count, std::uint64_t seed) {
  Scene scene = silo_scene(count);
  scene.emitters.at(0).seed = seed;
  World w = make_world(scene);
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, w, nullptr);
  const std::size_t gate = 2;  // static bodies in boundary order: left floor, right floor, gate
  EXPECT_EQ(w.bodies.motion[gate], MotionType::Static);
  CpuStepper stepper(w, settings);
  StepStats stats;
  // Settle behind the closed gate (0.5 s), then open it.
  while (w.time < 0.5) stats = stepper.step(w);
  EXPECT_LT(stats.energy.translational, 1e-3) << "J: fill " << seed << " has not settled before the gate opens";
  w.bodies.position[gate].z() = -100.0;  // m: out of reach
  const double opened = w.time;
  const double grain_mass = make_tetrahedral_grain(kRadius, 2 * kRadius, 2600).mass;  // kg
  Discharge d;
  while (w.time < opened + 1.5) {
    for (int i = 0; i < 50; ++i) stepper.step(w);
    std::size_t out = 0;
    for (std::size_t b : grains_of(w)) out += w.bodies.position[b].z() < -2 * kRadius ? 1 : 0;
    d.time.push_back(w.time - opened);
    d.mass.push_back(grain_mass * static_cast<double>(out));
    if (out > 0.8 * count) break;
  }
  return d;
}

// Thesis 7.3 / Beverloo: a silo drains at a rate that does not fall as its column shortens, where a
// bucket's would fall as sqrt(height). Criterion (revised 2026-12-08, written before its first run):
// over four fills (seeds 5-8), the mean of their discharged mass against time since the gate opened,
// over the middle of the discharge (10 % to 60 % of the grains out), is a straight line with
// R^2 > 0.98, and its rate over the second half of that window is at least 0.9 of the first half's (a
// Torricelli bucket, rate proportional to sqrt(mass left), gives 0.82 over the same window).
// Until 2026-12-08 this test ran one fill and asked |late / early - 1| <= 0.25. Nudging dt in its
// last digit moved that ratio to 1.18, 1.34 and 1.27 on the one fill, and over 0.87-1.71 on three
// fills (mean 1.26; docs/benchmarks/sim-cpufused-2026-12-08/silo_round_off.log): this small silo's
// discharge speeds up by about a quarter across the window, so the old two-sided check passed or failed
// by round-off, and R^2 over one fill fell below 0.98 in 3 of 9 nudged runs. What the physics asks,
// the rate not falling, is now checked on the mean of four fills.
TEST(GranularPhysics, SiloDischargeRateDoesNotFallAsTheColumnShortens) {
  const std::size_t count = 370;
  const std::vector<std::uint64_t> seeds = {5, 6, 7, 8};
  std::vector<Discharge> fills;
  for (std::uint64_t seed : seeds) fills.push_back(discharge_of_fill(count, seed));
  // Every fill samples the same times (same dt, same opening step): average sample by sample while
  // every fill has a sample.
  std::size_t samples = fills.front().time.size();
  for (const Discharge& d : fills) samples = std::min(samples, d.time.size());
  const double grain_mass = make_tetrahedral_grain(kRadius, 2 * kRadius, 2600).mass;  // kg
  const double total = grain_mass * static_cast<double>(count);
  std::vector<double> time, mass;
  for (std::size_t k = 0; k < samples; ++k) {
    double sum = 0;
    for (const Discharge& d : fills) {
      ASSERT_NEAR(d.time[k], fills.front().time[k], 1e-12) << "the fills sample different times";
      sum += d.mass[k];
    }
    const double mean = sum / static_cast<double>(fills.size());
    if (mean >= 0.1 * total && mean <= 0.6 * total) {
      time.push_back(fills.front().time[k]);
      mass.push_back(mean);
    }
  }
  ASSERT_GE(time.size(), 10u) << "the mean discharge did not pass through its middle (a fill jammed?)";
  const LineFit fit = fit_line(time, mass);
  EXPECT_GT(fit.r_squared, 0.98);
  const std::size_t half = time.size() / 2;
  const LineFit early = fit_line({time.begin(), time.begin() + half}, {mass.begin(), mass.begin() + half});
  const LineFit late = fit_line({time.begin() + half, time.end()}, {mass.begin() + half, mass.end()});
  EXPECT_GE(late.slope / early.slope, 0.9) << early.slope << " then " << late.slope << " kg/s";
  std::printf("[ silo     ] mean of %zu fills: %.3f kg/s, R^2 %.4f, late / early %.3f over %zu samples\n",
              fills.size(), fit.slope, fit.r_squared, late.slope / early.slope, time.size());
}

}  // namespace
}  // namespace ts::sim
