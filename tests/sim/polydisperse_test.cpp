// Grain types and size distributions (issue 18): `[[grain]]` tables and an emitter's `grain`,
// `fractions` and `size`; exact type and sieve counts; reproducible draws; mass kept over a run;
// the neighbour grid sized by the largest particle and the time step by the smallest grain.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "core/error.h"
#include "gpu/context.h"
#include "scene/checkpoint.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"
#include "scene/grain_mix.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "tests/input_error.h"
#include "tests/test_support.h"

namespace ts::sim {
using namespace ts::scene;  // these tests run whole scenes through the engine
namespace {

namespace fs = std::filesystem;

// A soft sand, two grain types (5 mm "coarse", 3 mm "fine"), a smooth floor, and `emitter` (lines 1-28
// before it; the emitter starts at line 29).
std::string two_types(const std::string& emitter, const std::string& simulation = "") {
  return fmt::format(R"([[material]]
name = "sand"
E = 1.0e6
nu = 0.3
restitution = 0.5
mu = 0.5
gamma_s = 2.0
density = 2600.0
[[material]]
name = "glass"
E = 2.0e6
nu = 0.25
restitution = 0.5
mu = 0.4
density = 2500.0
[[grain]]
name = "coarse"
radius = 5.0e-3
material = "sand"
[[grain]]
name = "fine"
radius = 3.0e-3
edge = 5.0e-3
material = "glass"
[[boundary]]
type = "plane"
material = "sand"

{}
[simulation]
duration = 0.1
{}
)",
                     emitter, simulation);
}

std::string fill(const std::string& keys, int count = 40) {
  return fmt::format(
      "[[emitter]]\ntype = \"fill\"\nmin = [-0.06, -0.06, 0.0]\nmax = [0.06, 0.06, 0.12]\ncount = {}\n{}",
      count, keys);
}

std::string parse_error(const std::string& text) {
  return test::input_error([&] { parse_scene(text, "scene.toml"); });
}

// Grains (bodies after the fixtures) by their particle radius (m), counted.
std::map<double, std::size_t> grains_by_radius(const Scene& scene, const World& world) {
  std::map<double, std::size_t> counts;
  for (std::size_t b = fixture_bodies(scene, world); b < world.bodies.size(); ++b)
    ++counts[world.particles.radius[world.bodies.first_particle[b]]];
  return counts;
}

double grain_mass(const Scene& scene, const World& world) {
  double mass = 0;  // kg
  for (std::size_t b = fixture_bodies(scene, world); b < world.bodies.size(); ++b)
    mass += 1 / world.bodies.inverse_mass[b];
  return mass;
}

TEST(GrainTypes, GrainTablesAndEmitterKeysParse) {
  const Scene s =
      parse_scene(two_types(fill("grain = [\"coarse\", \"fine\"]\nfractions = [1, 3]\n"
                                 "size = { distribution = \"lognormal\", median = 1.0, sigma = 0.1 }\n")),
                  "scene.toml");
  ASSERT_EQ(s.grains.size(), 2u);
  EXPECT_EQ(s.grains[1].name, "fine");
  EXPECT_EQ(s.grains[1].material, 1);
  EXPECT_DOUBLE_EQ(s.grains[1].edge, 5e-3);
  EXPECT_DOUBLE_EQ(s.grains[0].edge, 1e-2);  // default: touching spheres
  const Emitter& e = s.emitters.at(0);
  EXPECT_EQ(e.grains, (std::vector<std::uint16_t>{0, 1}));
  EXPECT_DOUBLE_EQ(e.fractions[0], 0.25);  // normalised
  EXPECT_EQ(e.size.distribution, SizeDistribution::Lognormal);
  EXPECT_NEAR(e.size.min, std::exp(-0.3), 1e-15);  // truncated at 3 sigma by default
  const Scene sieve = parse_scene(
      two_types(fill("grain = \"fine\"\nsize = { sieve = [[0.8, 1.0], [1.2, 3.0]] }\n")), "scene.toml");
  EXPECT_EQ(sieve.emitters[0].size.sieve, (std::vector<std::pair<double, double>>{{0.8, 0.25}, {1.2, 0.75}}));
}

TEST(GrainTypes, BadGrainAndSizeKeysNameFileLineAndKey) {
  EXPECT_EQ(parse_error(two_types(fill("grain = \"medium\"\n"))),
            "scene.toml:34: emitter.grain: no grain type named \"medium\" (have: \"coarse\", \"fine\")");
  EXPECT_EQ(
      parse_error(two_types(fill(""))),
      "scene.toml:29: emitter.grain: missing (required when the scene has several grain types: a [[grain]] "
      "name, or a list of them with fractions)");
  EXPECT_EQ(parse_error(two_types(fill("grain = [\"coarse\", \"fine\"]\nfractions = [1.0]\n"))),
            "scene.toml:35: emitter.fractions: must be an array of 2 numbers, one per grain type");
  EXPECT_EQ(parse_error(two_types(
                fill("grain = \"fine\"\nsize = { distribution = \"uniform\", min = 1.2, max = 0.8 }\n"))),
            "scene.toml:35: emitter.size.max: 0.8 is below min = 1.2");
  EXPECT_EQ(parse_error(two_types(fill("grain = \"fine\"\nsize = { sieve = [[0.8, 1.0], [0.8, 2.0]] }\n"))),
            "scene.toml:35: emitter.size.sieve: scale 0.8 is listed twice");
  EXPECT_EQ(parse_error(two_types(
                fill("grain = \"fine\"\nsize = { distribution = \"lognormal\", median = 1.0, sigma = 0.2, "
                     "min = 1.0, max = 1.0 }\n"))),
            "scene.toml:35: emitter.size.max: 1 must exceed min = 1 (one scale: no size key)");
  EXPECT_EQ(parse_error(two_types(fill("grain = \"fine\"\nsize = { distribution = \"gamma\" }\n"))),
            "scene.toml:35: emitter.size.distribution: \"gamma\" is not one of: uniform, lognormal, sieve");
  std::string twice = two_types(fill("grain = \"fine\"\n"));
  twice.replace(twice.find("name = \"fine\""), 13, "name = \"coarse\"");
  EXPECT_EQ(parse_error(twice), "scene.toml:21: grain.name: \"coarse\" is defined twice (also at line 16)");
  std::string unnamed = two_types(fill("grain = \"coarse\"\n"));
  unnamed.erase(unnamed.find("name = \"fine\"\n"), 14);
  EXPECT_EQ(parse_error(unnamed), "scene.toml:20: grain.name: missing (required)");
}

TEST(GrainTypes, TypeCountsFollowTheFractionsExactly) {
  const Scene s = parse_scene(
      two_types(fill("grain = [\"coarse\", \"fine\"]\nfractions = [0.3, 0.7]\nseed = 4\n")), "scene.toml");
  const World w = make_world(s);
  const auto counts = grains_by_radius(s, w);
  EXPECT_EQ(counts.at(5e-3), 12u);
  EXPECT_EQ(counts.at(3e-3), 28u);
  // Each grain carries its type's material and mass.
  for (std::size_t b = fixture_bodies(s, w); b < w.bodies.size(); ++b) {
    const std::uint32_t first = w.bodies.first_particle[b];
    const std::uint16_t type = w.particles.radius[first] == 5e-3 ? 0 : 1;
    EXPECT_EQ(w.particles.material[first], s.grains[type].material);
    EXPECT_DOUBLE_EQ(1 / w.bodies.inverse_mass[b], scaled_grain(s, type, 1.0).mass);
  }
}

TEST(GrainTypes, SieveClassesCarryTheirMassFractions) {
  const Scene s = parse_scene(
      two_types(fill("grain = \"coarse\"\nsize = { sieve = [[0.6, 0.2], [1.0, 0.8]] }\n", 60)), "scene.toml");
  const World w = make_world(s);
  const auto counts = grains_by_radius(s, w);
  // Number shares 0.2 / 0.216 : 0.8 / 1: 60 grains split 32.2 : 27.8, by largest remainder 32 : 28.
  EXPECT_EQ(counts.at(0.6 * 5e-3), 32u);
  EXPECT_EQ(counts.at(5e-3), 28u);
  const double small = 32 * std::pow(0.6, 3), large = 28.0;
  EXPECT_NEAR(small / (small + large), 0.2, 0.01);  // the mass fraction, to one grain's rounding
}

TEST(GrainTypes, UniformScalesStayInRangeAndRepeatWithTheSeed) {
  const Scene s = parse_scene(
      two_types(fill(
          "grain = \"coarse\"\nsize = { distribution = \"uniform\", min = 0.8, max = 1.2 }\nseed = 3\n")),
      "scene.toml");
  const std::vector<GrainDraw> draws = emitter_grain_draws(s.emitters[0]);
  ASSERT_EQ(draws.size(), 40u);
  double lo = 2, hi = 0, sum = 0;
  for (const GrainDraw& d : draws) {
    lo = std::min(lo, d.scale);
    hi = std::max(hi, d.scale);
    sum += d.scale;
  }
  EXPECT_GE(lo, 0.8);
  EXPECT_LE(hi, 1.2);
  EXPECT_GT(hi - lo, 0.3);  // spread over the range
  EXPECT_NEAR(sum / 40, 1.0, 0.05);
  EXPECT_EQ(world_bytes(make_world(s)), world_bytes(make_world(s)));
  Scene other = s;
  other.emitters[0].seed = 4;
  EXPECT_NE(emitter_grain_draws(other.emitters[0])[0].scale, draws[0].scale);
}

// 4,000 lognormal draws: ln scale has the median's log as its mean (within 3 standard errors) and
// sigma as its spread, less the 1.3 % the default truncation at 3 sigma takes off (within 4 %); none
// falls outside the truncation.
TEST(GrainTypes, LognormalScalesHaveTheRequestedMedianAndSpread) {
  Emitter e;
  e.count = 4000;
  e.seed = 12;
  e.size.distribution = SizeDistribution::Lognormal;
  e.size.median = 1.1;
  e.size.sigma = 0.2;
  e.size.min = 1.1 * std::exp(-0.6);
  e.size.max = 1.1 * std::exp(0.6);
  double sum = 0, squares = 0;
  for (const GrainDraw& d : emitter_grain_draws(e)) {
    ASSERT_GE(d.scale, e.size.min);
    ASSERT_LE(d.scale, e.size.max);
    sum += std::log(d.scale);
    squares += std::log(d.scale) * std::log(d.scale);
  }
  const double mean = sum / 4000, sd = std::sqrt(squares / 4000 - mean * mean);
  EXPECT_NEAR(mean, std::log(1.1), 3 * 0.2 / std::sqrt(4000.0));
  EXPECT_NEAR(sd / (0.9866 * 0.2), 1.0, 0.04);
}

// The single `[grain]` and one `[[grain]]` named by the emitter place the same grains, bit for bit.
TEST(GrainTypes, OneNamedGrainTypeBuildsTheWorldOfTheSingleGrainTable) {
  const std::string emitter = fill("seed = 5\n");
  std::string single = two_types(emitter);
  single.erase(single.find("[[grain]]\nname = \"fine\""),
               single.find("[[boundary]]") - single.find("[[grain]]\nname = \"fine\""));
  std::string table = single;
  table.replace(table.find("[[grain]]\nname = \"coarse\"\n"), 26, "[grain]\n");
  const Scene a = parse_scene(single, "a.toml"), b = parse_scene(table, "b.toml");
  ASSERT_EQ(a.grains.size(), 1u);
  EXPECT_EQ(world_bytes(make_world(a)), world_bytes(make_world(b)));
}

// Over a run with a fill and a pour of mixed types and sizes, the grains' total mass is the sum of
// the grains emitted, and no grain is lost (mass conservation).
TEST(GrainTypes, RunKeepsTheMassOfEveryGrainEmitted) {
  const fs::path dir = test::temp_dir();
  const std::string pour =
      "[[emitter]]\ntype = \"pour\"\nmin = [-0.04, -0.04, 0.15]\nmax = [0.04, 0.04, 0.2]\ncount = 10\nrate = "
      "200\n"
      "grain = [\"coarse\", \"fine\"]\nfractions = [0.5, 0.5]\nsize = { sieve = [[0.8, 0.5], [1.0, 0.5]] }\n";
  const Scene s = parse_scene(two_types(fill("grain = [\"coarse\", \"fine\"]\nfractions = [0.5, 0.5]\n"
                                             "size = { distribution = \"uniform\", min = 0.8, max = 1.2 }\n",
                                             20) +
                                        pour),
                              dir / "scene.toml");
  double emitted = 0;  // kg
  for (const Emitter& e : s.emitters)
    for (const GrainDraw& d : emitter_grain_draws(e)) emitted += scaled_grain(s, d.type, d.scale).mass;
  World last;
  RunHooks hooks;
  hooks.on_output = [&](const World& w, const StepStats&, std::int64_t) { last = w; };
  Scene run = s;
  run.output.every = 200;
  run_scene(run, dir / "out", hooks);
  EXPECT_EQ(last.bodies.size() - fixture_bodies(s, last), 30u);
  EXPECT_NEAR(grain_mass(s, last), emitted, 1e-12 * emitted);
  for (std::size_t b = fixture_bodies(s, last); b < last.bodies.size(); ++b)
    EXPECT_GT(last.bodies.position[b].z(), 0.0) << "grain " << b << " fell through the floor";
}

// The automatic step is the smallest grain's: adding a coarser type changes nothing, a finer one
// shortens it.
TEST(GrainTypes, TimeStepIsBoundByTheSmallestGrain) {
  auto bound = [](const std::string& keys) {
    const Scene s = parse_scene(two_types(fill(keys)), "scene.toml");
    return scene_time_step_bound(s, make_world(s), 1.0).recommended;
  };
  const double fine = bound("grain = \"fine\"\n"), coarse = bound("grain = \"coarse\"\n");
  const double both = bound("grain = [\"coarse\", \"fine\"]\nfractions = [0.5, 0.5]\n");
  EXPECT_LT(fine, coarse);
  EXPECT_DOUBLE_EQ(both, fine);
  // A size distribution: its smallest scale sets the step.
  const double scaled =
      bound("grain = \"coarse\"\nsize = { distribution = \"uniform\", min = 0.5, max = 1.0 }\n");
  EXPECT_DOUBLE_EQ(scaled, bound("grain = \"coarse\"\nsize = { sieve = [[0.5, 1.0]] }\n"));
  EXPECT_LT(scaled, coarse);
}

// A 3 mm sphere and a 0.5 mm one touching: their centres are 3.49 mm apart, farther than two small
// diameters, so a grid sized by the small sphere would not look far enough. Both engines find it.
World big_and_small() {
  World w;
  w.materials = {Material{}};
  w.materials[0].youngs_modulus = 1e6;
  w.gravity = Eigen::Vector3d::Zero();
  BodyDesc big, small;
  big.inverse_mass = 1.0;
  big.inverse_inertia = Eigen::Matrix3d::Identity();
  small = big;
  small.position = Eigen::Vector3d(3.49e-3, 0.0, 0.0);
  add_body(w, big, {Eigen::Vector3d::Zero()}, {3e-3}, 0);
  add_body(w, small, {Eigen::Vector3d::Zero()}, {0.5e-3}, 0);
  return w;
}

TEST(GrainTypes, NeighbourGridFromTheLargestParticleFindsABigSmallContact) {
  World cpu_world = big_and_small();
  StepSettings settings;
  settings.dt = 1e-6;
  CpuStepper cpu(cpu_world, settings);
  EXPECT_EQ(cpu.step(cpu_world).contacts, 1u);
  EXPECT_LT(cpu_world.bodies.linear_velocity[0].x(), 0.0);  // pushed apart
  World gpu_world = big_and_small();
  gpu::Context context;
  GpuStepper gpu(context, gpu_world, settings, Precision::Float);
  gpu.step(1);
  EXPECT_EQ(gpu.statistics().contacts, 1u);
  gpu.download(gpu_world);
  EXPECT_LT(gpu_world.bodies.linear_velocity[0].x(), 0.0);
}

}  // namespace
}  // namespace ts::sim
