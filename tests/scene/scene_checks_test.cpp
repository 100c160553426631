// Stops instead of nonsense (docs/reliability.md, "Criteria"): forces no contact holds and impacts the
// automatic step cannot resolve are refused before the first step naming file:line:key; a grain
// passing through a wall stops the run on both engines; velocity clamps that do not die out stop it.
#include "scene/scene_checks.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "gpu/context.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"
#include "scene/scene_runner.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

namespace fs = std::filesystem;

// A bundled scene with some lines replaced, written as dir/NAME and loaded from there.
Scene patched(const std::string& asset, const std::vector<std::pair<std::string, std::string>>& edits,
              const fs::path& dir, const std::string& name = "scene.toml") {
  std::string text = read_file(test::asset(asset));
  for (const auto& [from, to] : edits) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  }
  write_file_atomically(dir / name, text);
  return load_scene(dir / name);
}

// The 1-based line of the first line of `file` starting with `prefix`.
int line_of(const fs::path& file, const std::string& prefix) {
  const std::string text = read_file(file);
  int line = 1;
  for (std::size_t at = 0; at < text.size(); at = text.find('\n', at) + 1, ++line) {
    if (text.compare(at, prefix.size(), prefix) == 0) return line;
    if (text.find('\n', at) == std::string::npos) break;
  }
  return 0;
}

// The message of the InputError that check_scene_forces throws on `scene`, "" when none.
std::string forces_error(const Scene& scene) {
  WorldSources sources;
  const World world = make_world(scene, &sources);
  try {
    check_scene_forces(scene, world, sources, resolve_time_step(scene, world, nullptr));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

double number_after(const std::string& text, const std::string& before) {
  std::smatch m;
  EXPECT_TRUE(std::regex_search(text, m, std::regex(before + R"(([0-9.]+(e[+-]?[0-9]+)?))"))) << text;
  return m.empty() ? 0 : std::stod(m[1].str());
}

TEST(SceneChecks, GravityNoContactCanHoldIsRefusedNamingTheKeyAndTheLargestThatFits) {
  const fs::path dir = test::temp_dir();
  const Scene scene =
      patched("scenes/free_fall.toml", {{"gravity = [0.0, 0.0, -9.81]", "gravity = [0, 0, -1e10]"}}, dir);
  const std::string where =
      fmt::format("{}:{}: gravity:", (dir / "scene.toml").string(), line_of(dir / "scene.toml", "gravity"));
  try {
    run_scene(scene, dir / "out");
    FAIL() << "ran";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(where, 0), 0u) << message;
    EXPECT_NE(message.find("no contact can hold a grain's own weight"), std::string::npos) << message;
    // The largest |g| it names passes the weight check, a little more does not (the design speed
    // set by hand keeps the impact check out of it).
    const double largest = number_after(message, "at most \\|g\\| = ");
    Scene below = patched("scenes/free_fall.toml",
                          {{"dt = \"auto\"", "dt = \"auto\"\nmax_impact_speed = 0.5"}}, dir, "b.toml");
    below.gravity = {0, 0, -0.99 * largest};
    EXPECT_EQ(forces_error(below), "");
    below.gravity = {0, 0, -1.01 * largest};
    EXPECT_NE(forces_error(below).find("gravity"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "metrics.csv"));  // refused before the first step
}

TEST(SceneChecks, ImpactTheAutomaticStepCannotResolveIsRefusedWithTheLargestSpeedThatFits) {
  const fs::path dir = test::temp_dir();
  Scene scene =
      patched("scenes/free_fall.toml", {{"dt = \"auto\"", "dt = \"auto\"\nmax_impact_speed = 5000.0"}}, dir);
  const std::string message = forces_error(scene);
  const std::string where = fmt::format("{}:{}: simulation.max_impact_speed:", (dir / "scene.toml").string(),
                                        line_of(dir / "scene.toml", "max_impact_speed"));
  EXPECT_EQ(message.rfind(where, 0), 0u) << message;
  EXPECT_NE(message.find("the step cannot resolve such an impact"), std::string::npos) << message;
  const double largest = number_after(message, "at most ");
  EXPECT_GT(largest, 10.0);
  EXPECT_LT(largest, 5000.0);
  scene.simulation.max_impact_speed = 0.99 * largest;
  EXPECT_EQ(forces_error(scene), "");
  scene.simulation.max_impact_speed = 1.01 * largest;
  EXPECT_NE(forces_error(scene), "");
  // A fast launch names the emitter's velocity; a time step given by hand is not refused.
  Scene launched = patched("scenes/free_fall.toml",
                           {{"seed = 1", "seed = 1\nvelocity = [0.0, 0.0, -3000.0]"}}, dir, "l.toml");
  EXPECT_NE(forces_error(launched).find(fmt::format(":{}: emitter.velocity:", launched.emitters[0].line)),
            std::string::npos)
      << forces_error(launched);
  launched.simulation.dt = 1e-6;
  EXPECT_EQ(forces_error(launched), "");
}

TEST(SceneChecks, EveryBundledAndReferenceSceneStartsWithoutTrippingACheck) {
  for (const char* name : {"free_fall", "two_grain_collision", "pile", "hourglass", "prop_drop", "blade",
                           "crumble", "scrape", "reference/bed", "reference/bed_tile", "reference/bounce", "reference/coarse_bed",
                           "reference/coarse_pile", "reference/column", "reference/elastic_box",
                           "reference/heap", "reference/silo", "reference/silo_mankoc"}) {
    const Scene scene = load_scene(test::asset(std::string("scenes/") + name + ".toml"));
    EXPECT_EQ(forces_error(scene), "") << name;
  }
}

// A grain dropped hard enough to go through the floor in a few steps (|g| below the weight limit, so
// the run starts): the CPU reference and the GPU pipeline stop it, naming the floor and the grain.
Scene falling_through(const fs::path& dir) {
  return patched(
      "scenes/free_fall.toml",
      {{"gravity = [0.0, 0.0, -9.81]", "gravity = [0, 0, -3e4]"}, {"duration = 0.15", "duration = 0.01"}},
      dir);
}

void expect_stopped_at_the_floor(const Scene& scene, const fs::path& out, const StepperFactory& factory) {
  try {
    run_scene(scene, out, {}, factory);
    FAIL() << "no stop";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.code(), ExitCode::Unstable) << message;
    const int floor = line_of(scene.file, "[[boundary]]");
    EXPECT_NE(message.find(fmt::format("passed through the plane of [[boundary]] at line {}", floor)),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("of grain body "), std::string::npos) << message;
  }
  EXPECT_TRUE(fs::exists(out / "last_good.ply"));
}

TEST(SceneChecks, GrainThroughTheFloorStopsTheCpuReference) {
  const fs::path dir = test::temp_dir();
  expect_stopped_at_the_floor(falling_through(dir), dir / "out", {});
  Scene off = falling_through(dir);
  off.simulation.step.check_penetration = false;
  EXPECT_NO_THROW(run_scene(off, dir / "off"));  // the old silent run
}

TEST(SceneChecks, GrainThroughTheFloorStopsTheGpuPipelineFromItsCounters) {
  gpu::Context context;
  const fs::path dir = test::temp_dir();
  expect_stopped_at_the_floor(falling_through(dir), dir / "out", [&](const StepSettings& s) {
    return std::make_unique<GpuStepper>(context, s);
  });
}

// Spheres moving through a plane and (from inside out) a cylinder, two radii in a step, and one
// pressed a little past the floor that stays there: both engines find particle 1 (the lowest id of
// those wholly behind a wall) at the floor, count both, and leave the one only partly behind alone.
World through_walls() {
  World w;
  w.materials = {Material{}};
  w.gravity = Eigen::Vector3d::Zero();
  const double r = 1e-3, inverse_mass = 1 / 1e-5, inverse_inertia = 1 / 4e-12;
  w.walls.planes.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0});
  w.walls.cylinders.push_back({Eigen::Vector2d::Zero(), 0.05, -1.0, 1.0, 0});
  auto sphere = [&](const Eigen::Vector3d& x, const Eigen::Vector3d& v) {
    BodyDesc d;
    d.position = x;
    d.linear_velocity = v;
    d.inverse_mass = inverse_mass;
    d.inverse_inertia = Eigen::Matrix3d::Identity() * inverse_inertia;
    add_body(w, d, {Eigen::Vector3d::Zero()}, {r}, 0);
  };
  sphere({0.02, 0.0, -0.5 * r}, Eigen::Vector3d::Zero());  // particle 0: half a radius past the floor
  sphere({0.0, 0.0, 0.5 * r}, {0, 0, -2.0});               // particle 1: through the floor
  sphere({0.05 - 0.5 * r, 0.0, 0.02}, {2.0, 0, 0});        // particle 2: out through the cylinder
  return w;
}

TEST(SceneChecks, BothEnginesReportTheSamePenetrationAndCountEveryOne) {
  StepSettings s;
  s.dt = 1e-3;  // 2 mm per step at 2 m/s: two spheres are wholly behind their walls after the first
  s.cfl = 0;
  s.check_energy = false;
  gpu::Context context;
  for (int engine = 0; engine < 2; ++engine) {
    World w = through_walls();
    std::unique_ptr<Stepper> stepper;
    if (engine == 0) stepper = std::make_unique<CpuStepper>(s);
    if (engine == 1) stepper = std::make_unique<GpuStepper>(context, s, Precision::Float);
    stepper->load(w);
    EXPECT_NO_THROW(stepper->advance(w, 1)) << stepper->engine();  // nobody wholly behind yet
    Penetration found;
    try {
      stepper->advance(w, 1);
      ADD_FAILURE() << stepper->engine() << ": no penetration";
    } catch (const WallPenetration& e) {
      found = e.penetration();
    }
    EXPECT_EQ(found.particle, 1u) << stepper->engine();
    EXPECT_EQ(found.wall, 0) << stepper->engine();
    EXPECT_EQ(found.count, 2u) << stepper->engine();  // the floor and the cylinder
  }
}

TEST(SceneChecks, SustainedVelocityClampsStopTheRunAndPassingOnesDoNot) {
  ClampWatch watch(true);
  EXPECT_NO_THROW(watch.interval(5000, 1000, 0.1));      // an explosion of clamps...
  EXPECT_NO_THROW(watch.interval(2000, 1000, 0.2));      // ...dying out
  EXPECT_NO_THROW(watch.interval(500, 1000, 0.3));       // fewer than one per step
  EXPECT_NO_THROW(watch.interval(2000, 1000, 0.4));      // saturated after one that was not
  EXPECT_THROW(watch.interval(2000, 1000, 0.5), Error);  // not dying out: two saturated intervals, no fewer
  ClampWatch off(false);
  off.interval(2000, 1000, 0.1);
  EXPECT_NO_THROW(off.interval(2000, 1000, 0.2));

  // Grains falling with no floor, the CFL speed set far below what gravity reaches: every grain is
  // clamped every step once it gets there, and the run stops with exit 4 and the last good state.
  const fs::path dir = test::temp_dir();
  Scene scene = patched("scenes/free_fall.toml",
                        {{"dt = \"auto\"", "dt = 1e-5\ncfl = 0.001"}, {"every = 200", "every = 100"}}, dir);
  scene.boundaries.clear();
  try {
    run_scene(scene, dir / "out");
    FAIL() << "no stop";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unstable);
    EXPECT_NE(std::string(e.what()).find("velocity clamps in the last 100 steps"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "last_good.ply"));
  scene.simulation.check_clamps = false;
  scene.simulation.duration = 0.04;
  EXPECT_NO_THROW(run_scene(scene, dir / "off"));
}

}  // namespace
}  // namespace ts::scene
