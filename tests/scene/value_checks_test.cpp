// The value checker (core/checked_values.h) as scenes meet it: numbers that are finite but turn into
// nonsense in the arithmetic they feed (a norm that overflows, a step count below one) are refused
// naming file:line:key, and the state a run ends in is checked like every other step.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "core/atomic_file.h"
#include "core/checked_values.h"
#include "core/error.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "tests/input_error.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

namespace fs = std::filesystem;

std::string parse_error(const std::string& text) {
  return test::input_error([&] { parse_scene(text, "scene.toml"); });
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ValueChecks, PlaneNormalWhoseNormOverflowsIsRefusedNamingFileLineAndKey) {
  // kCoarseSand is 11 lines; the boundary table starts on line 12, its normal is line 15.
  const std::string text =
      std::string(test::kCoarseSand) + test::smooth_plane("[0.0, 0.0, 0.0]", "[1.0e200, 0.0, 0.0]");
  const std::string error = parse_error(text);
  EXPECT_TRUE(contains(error, "scene.toml:15: boundary.normal: vector has a norm of 1e+200")) << error;
  // The same normal at a size normalising can take still reads as the unit x axis.
  const Scene ok = parse_scene(
      std::string(test::kCoarseSand) + test::smooth_plane("[0.0, 0.0, 0.0]", "[1.0e100, 0.0, 0.0]"),
      "scene.toml");
  EXPECT_EQ(ok.boundaries.at(0).normal, Eigen::Vector3d::UnitX());
}

TEST(ValueChecks, PropQuaternionWhoseNormOverflowsIsRefusedNamingFileLineAndKey) {
  const fs::path dir = test::temp_dir();
  write_file_atomically(dir / "scene.toml", std::string(test::kCoarseSand) +
                                                fmt::format(R"([[prop]]
body = "{}"
orientation = [1.0e200, 0.0, 0.0, 0.0]
material = "sand"
)",
                                                            test::asset("bodies/plate.body.json").string()));
  const std::string error = test::input_error([&] { load_scene(dir / "scene.toml"); });
  EXPECT_TRUE(
      contains(error, "scene.toml:14: prop.orientation: quaternion [w, x, y, z] has a norm of 1e+200"))
      << error;
}

TEST(ValueChecks, TimeStepsThatLeaveNoStepAreRefused) {
  const std::string base = std::string(test::kCoarseSand) + "[simulation]\nduration = 0.5\n";
  const std::string infinite = parse_error(base + "dt = inf\n");
  EXPECT_TRUE(contains(infinite, "scene.toml:14: simulation.dt: dt must be finite and > 0 (got inf)"))
      << infinite;
  const std::string too_long = parse_error(base + "dt = 2.0\n");
  EXPECT_TRUE(contains(
      too_long,
      "scene.toml:14: simulation.dt: dt = 2 s is longer than the whole run of 0.5 s: not one step fits"))
      << too_long;
  const std::string vast = parse_error(base + "dt = 1.0e10\n");  // rounded to zero steps before
  EXPECT_TRUE(contains(vast, "not one step fits")) << vast;
  EXPECT_EQ(parse_scene(base + "dt = 0.5\n", "scene.toml").simulation.dt, 0.5);  // one step is a run
}

TEST(ValueChecks, StepCountRefusesWhatLeavesNoStepOrOverflowsTheCounter) {
  const Where where{"run.toml", 3, "simulation.dt"};
  EXPECT_EQ(checked_step_count(1.0, 0.25, where), 4);
  EXPECT_EQ(checked_step_count(1.0, 1.0, where), 1);
  const std::string nan = test::input_error([&] { checked_step_count(1.0, std::nan(""), where); });
  EXPECT_TRUE(contains(nan, "run.toml:3: simulation.dt: dt must be finite and > 0")) << nan;
  const std::string huge = test::input_error([&] { checked_step_count(1e300, 1e-300, where); });
  EXPECT_TRUE(contains(huge, "do not fit a step counter")) << huge;
  const std::string tiny =
      test::input_error([&] { checked_unit_vector(Eigen::Vector3d(1e-200, 0, 0), where); });
  EXPECT_TRUE(contains(tiny, "outside what normalising can take")) << tiny;
}

TEST(ValueChecks, VelocityWhoseEnergyOverflowsIsRefusedNamingFileLineAndKey) {
  const std::string text =
      std::string(test::kCoarseSand) +
      test::box_emitter("fill", "[0.0, 0.0, 0.0]", "[0.1, 0.1, 0.1]", 1, "velocity = [1.0e300, 0.0, 0.0]\n");
  const std::string error = parse_error(text);
  EXPECT_TRUE(
      contains(error, "scene.toml:17: emitter.velocity: a speed of 1e+300 m/s exceeds the speed of light"))
      << error;
}

// A dt by hand may exceed the stability bound by at most kHandTimeStepFactor: beyond it the run is
// refused before the first step, naming the key, the factor and the largest dt that would run; within
// it (and with check_time_step = false) it warns and runs.
TEST(ValueChecks, HandTimeStepFarAboveTheStabilityBoundIsRefusedNamingTheKeyAndWhatWouldRun) {
  const std::string base = std::string(test::kCoarseSand) +
                           test::smooth_plane("[0.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]") +
                           test::box_emitter("fill", "[-0.03, -0.03, 0.01]", "[0.03, 0.03, 0.05]", 1) +
                           "[simulation]\nduration = 0.001\n";
  const Scene automatic = parse_scene(base, "scene.toml");
  const World world = make_world(automatic);
  const double bound = resolve_time_step(automatic, world, nullptr);
  const auto with_dt = [&](double dt, const std::string& extra = "") {
    return parse_scene(base + fmt::format("dt = {:.17g}\n", dt) + extra, "scene.toml");
  };
  std::string warning;
  EXPECT_EQ(resolve_time_step(with_dt(1.5 * bound), world, &warning), 1.5 * bound);
  EXPECT_TRUE(contains(warning, "exceeds the stable bound")) << warning;
  const std::string refused = test::input_error([&] { resolve_time_step(with_dt(3 * bound), world, nullptr); });
  EXPECT_TRUE(refused.starts_with("scene.toml:") && contains(refused, ": simulation.dt: dt = ")) << refused;
  EXPECT_TRUE(contains(refused, "3 times the bound, where a time step by hand may exceed it by at most 2x"))
      << refused;
  EXPECT_TRUE(contains(refused, fmt::format("use dt <= {:.3g} s", 2 * bound))) << refused;
  warning.clear();
  EXPECT_EQ(resolve_time_step(with_dt(3 * bound, "check_time_step = false\n"), world, &warning), 3 * bound);
  EXPECT_TRUE(contains(warning, "exceeds the stable bound")) << warning;
}

// A grain's mass and inertia feed 1/m, a 3x3 inverse and m v^2: density = 1e200 wrote a NaN
// rotational energy at exit 0 (found by fuzz_scene). Refused before the world is built, naming the
// [grain] table's line and what would fit.
TEST(ValueChecks, GrainWhoseMassLeavesDoubleArithmeticIsRefusedNamingTheGrainTable) {
  std::string text = std::string(test::kCoarseSand) +
                     test::box_emitter("fill", "[-0.03, -0.03, 0.01]", "[0.03, 0.03, 0.05]", 1);
  text.replace(text.find("density = 2600.0"), 16, "density = 1.0e200");
  const Scene scene = parse_scene(text, "scene.toml");
  const std::string error = test::input_error([&] { make_world(scene); });
  EXPECT_TRUE(contains(error, "scene.toml:9: grain: a grain weighs")) << error;
  EXPECT_TRUE(contains(error, "needs both within 1e-100..1e+100")) << error;
}

// One grain thrown at the floor so fast that the run's single step carries it wholly through: the
// engines see a step's result only when the next step starts, and there is none.
TEST(ValueChecks, GrainThroughTheFloorOnTheLastStepStopsTheRunWithExit4) {
  const fs::path dir = test::temp_dir();
  write_file_atomically(dir / "scene.toml",
                        std::string(test::kCoarseSand) +
                            test::smooth_plane("[0.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]") +
                            test::box_emitter("fill", "[-0.03, -0.03, 0.01]", "[0.03, 0.03, 0.05]", 1,
                                              "velocity = [0.0, 0.0, -20.0]\n") +
                            "[simulation]\nduration = 0.01\ndt = 0.01\ncheck_time_step = false\n");
  const Scene scene = load_scene(dir / "scene.toml");
  try {
    run_scene(scene, dir / "out");
    FAIL() << "a grain 0.2 m below the floor ended the run at exit 0";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unstable) << e.what();
    EXPECT_TRUE(contains(e.what(), "has passed through")) << e.what();
    EXPECT_TRUE(contains(e.what(), "the plane of [[boundary]] at line 12")) << e.what();
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "last_good.ply"));
}

}  // namespace
}  // namespace ts::scene
