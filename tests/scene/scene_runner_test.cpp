#include "scene/scene_runner.h"
#include "scene/scene_world.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

std::vector<std::string> lines_of(const std::filesystem::path& file) {
  std::istringstream in(read_file(file));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(SceneRunner, FreeFallSceneFollowsTheParabolaAndWritesOutputs) {
  Scene scene = load_scene(test::asset("scenes/free_fall.toml"));
  scene.simulation.duration = 0.02;  // s: still in the air (the fall lasts 0.1 s)
  scene.output.every = 250;
  scene.output.vtp = true;
  const World start = make_world(scene);
  const auto dir = test::temp_dir();
  double worst = 0;
  RunHooks hooks;
  hooks.on_output = [&](const World& w, const StepStats& stats, std::int64_t) {
    EXPECT_EQ(stats.contacts + stats.wall_contacts, 0u);
    for (std::size_t b = 0; b < w.bodies.size(); ++b) {
      const double expected = start.bodies.position[b].z() - 0.5 * 9.81 * w.time * w.time;
      worst = std::max(worst, std::abs(w.bodies.position[b].z() - expected));
    }
  };
  const RunResult r = run_scene(scene, dir, hooks);
  EXPECT_EQ(r.time_step_warning, "");  // dt = "auto"
  EXPECT_EQ(r.steps, static_cast<std::int64_t>(std::ceil(0.02 / r.dt - 1e-9)));
  EXPECT_LT(worst, 9.81 * r.dt * 0.02);  // forward Euler lags by g dt t / 2
  const auto csv = lines_of(dir / "metrics.csv");
  ASSERT_EQ(static_cast<std::int64_t>(csv.size()), 1 + r.outputs);
  EXPECT_EQ(csv[0].rfind("step,time_s,grains,", 0), 0u);
  const auto ply = read_file(dir / "particles_000001.ply");
  const std::size_t header = ply.find("end_header\n") + 11;
  EXPECT_EQ(ply.size() - header, 32u * 20u);  // 32 particles of 4 floats + 1 uint
  EXPECT_NE(read_file(dir / "particles_000001.vtp").find("NumberOfPoints=\"32\""), std::string::npos);
}

TEST(SceneRunner, TwoGrainCollisionConservesMomentumAndDumpsContacts) {
  Scene scene = load_scene(test::asset("scenes/two_grain_collision.toml"));
  scene.output.every = 50;
  const auto dir = test::temp_dir();
  std::size_t contacts_seen = 0;
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  RunHooks hooks;
  hooks.on_output = [&](const World& w, const StepStats& stats, std::int64_t) {
    contacts_seen += stats.contacts;
    momentum = linear_momentum(w);
  };
  run_scene(scene, dir, hooks);
  EXPECT_GT(contacts_seen, 0u);
  EXPECT_LT(momentum.norm(), 1e-9);  // equal and opposite
  std::size_t rows = 0;
  for (std::int64_t i = 0; std::filesystem::exists(dir / fmt::format("contacts_{:06d}.csv", i)); ++i) {
    rows += lines_of(dir / fmt::format("contacts_{:06d}.csv", i)).size() - 1;
  }
  EXPECT_EQ(rows, contacts_seen);
}

TEST(SceneRunner, PourEmitterAddsGrainsOverTime) {
  Scene scene = load_scene(test::asset("scenes/pile.toml"));
  scene.simulation.duration = 0.005;
  scene.boundaries.at(0).size = Eigen::Vector2d(0.04, 0.04);  // m: a smaller rough floor keeps the test fast
  scene.output = OutputSettings{};
  scene.output.every = 100;
  const RunResult r = run_scene(scene, test::temp_dir());
  EXPECT_EQ(r.grains, 10u);  // 2000 grains/s: one at t = 0, then one each 0.5 ms before 5 ms
}

// The bench's way to say what a scene cannot (the oedometer's sphere grains): the hook's world is the
// one that runs, from the first output on.
TEST(SceneRunner, EditInitialWorldHookChangesTheWorldThatRuns) {
  Scene scene = load_scene(test::asset("scenes/free_fall.toml"));
  scene.simulation.duration = 0.001;  // s
  scene.output.every = 1000000;
  RunHooks hooks;
  hooks.edit_initial_world = [](World& w) {
    for (Eigen::Vector3d& v : w.bodies.linear_velocity) v = Eigen::Vector3d(0, 0, 1);  // m/s, thrown up
  };
  std::vector<double> speeds;
  hooks.on_output = [&](const World& w, const StepStats&, std::int64_t) {
    speeds.push_back(w.bodies.linear_velocity[0].z());
  };
  run_scene(scene, test::temp_dir(), hooks);
  ASSERT_EQ(speeds.size(), 2u);  // t = 0 and the end
  EXPECT_EQ(speeds[0], 1.0);
  EXPECT_NEAR(speeds[1], 1.0 - 9.81 * 0.001, 1e-3);
}

TEST(SceneRunner, TooLargeTimeStepWarnsThenBlowsUpWithTheLastGoodState) {
  const auto dir = test::temp_dir();
  std::ofstream(dir / "box.toml") << R"(
[[material]]
name = "sand"
E = 1.0e7
nu = 0.3
restitution = 0.5
mu = 0.5
density = 2600.0
[grain]
radius = 1.0e-3
material = "sand"
[[emitter]]
type = "fill"
min = [-0.006, -0.006, 0.0]
max = [0.006, 0.006, 0.012]
count = 8
[[boundary]]
type = "box"
min = [-0.006, -0.006, 0.0]
max = [0.006, 0.006, 0.1]
material = "sand"
[simulation]
duration = 4.0
dt = 2.0e-3   # a hundred times the bound
check_time_step = false
[output]
every = 10
)";
  const Scene scene = load_scene(dir / "box.toml");
  World w = make_world(scene);
  std::string warning;
  resolve_time_step(scene, w, &warning);
  EXPECT_NE(warning.find("exceeds the stable bound"), std::string::npos);
  try {
    run_scene(scene, dir / "out");
    FAIL() << "no blow-up";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unstable) << e.what();
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "last_good.ply"));
}

}  // namespace
}  // namespace ts::scene

namespace ts::scene {
namespace {

// `tetrasand sim --timings` on the GPU with the spring model: the run finishes (the kernel report
// used to read a destroyed stepper), reports the spring slots and the host-GPU round trips, and
// metrics.csv has the slots' column.
TEST(SimCommand, GpuRunWithSpringsAndTimingsReportsBoth) {
  std::ifstream in(test::asset("scenes/two_grain_collision.toml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string scene = text.str();
  const std::size_t at = scene.find("[simulation]");
  ASSERT_NE(at, std::string::npos);
  scene.insert(at + std::string("[simulation]").size(), "\ntangential = \"spring\"");
  const std::filesystem::path dir = test::temp_dir();
  write_file_atomically(dir / "springs.toml", scene);
  std::string output;
  const int code = test::run_tetrasand(fmt::format("sim '{}' -o '{}' --backend gpu --timings",
                                                   (dir / "springs.toml").string(), (dir / "out").string()),
                                       &output);
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("sim/contact_forces.comp"), std::string::npos) << output;
  EXPECT_NE(output.find("spring slots: 0 overflows"), std::string::npos) << output;
  // The round trips: none in the steps between outputs (docs/architecture.md, where the host waits).
  EXPECT_TRUE(std::regex_search(output, std::regex(R"(sim steps between outputs \(\d+\) +0 )"))) << output;
  std::ifstream csv(dir / "out" / "metrics.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",spring_overflows"), std::string::npos) << header;
}

}  // namespace
}  // namespace ts::scene
