// Granular column collapse (issue 7, small version of the validation run in bench/validation): a
// column released from a cylinder spreads further, relative to its radius, the taller it is
// (Lube et al. 2004; Lajeunesse et al. 2004). Too few grains here to test the exponents.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/cpu_stepper.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "tests/test_support.h"

namespace ts::sim {
using namespace ts::scene;  // these tests run whole scenes through the engine
namespace {

struct Collapse {
  double r0 = 0, h0 = 0, runout = 0;  // m
  double aspect() const { return h0 / r0; }
  double normalised_runout() const { return (runout - r0) / r0; }
};

// 95th percentile of the grains' outer extent: height, or horizontal distance from the axis (m).
double extent(const World& world, bool vertical) {
  std::vector<double> v;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] != MotionType::Dynamic) continue;
    const Eigen::Vector3d& x = world.bodies.position[b];
    v.push_back((vertical ? x.z() : std::hypot(x.x(), x.y())) + world.bodies.bounding_radius[b]);
  }
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(0.95 * static_cast<double>(v.size() - 1))];
}

// reference/column.toml with `count` grains in a cylinder of radius r0 (m) on a 30 cm floor: settle
// for `settle` s, remove the cylinder, spread for `spread` s.
Collapse collapse(double r0, std::size_t count, double settle, double spread) {
  Scene scene = load_scene(test::asset("scenes/reference/column.toml"));
  scene.emitters.at(0).radius = r0;
  scene.emitters.at(0).count = count;
  scene.boundaries.at(0).radius = r0 + 1e-4;
  scene.boundaries.at(1).size = Eigen::Vector2d(0.3, 0.3);
  World world = make_world(scene);
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, world, nullptr);
  CpuStepper stepper(world, settings);
  for (double t = 0; t < settle; t += settings.dt) stepper.step(world);
  Collapse c{r0, extent(world, true), 0};
  world.walls.cylinders.clear();
  for (double t = 0; t < spread; t += settings.dt) stepper.step(world);
  c.runout = extent(world, false);
  return c;
}

TEST(ColumnCollapse, RunoutGrowsWithAspectRatio) {
  const Collapse squat = collapse(0.053, 60, 0.8, 0.6);
  const Collapse tall = collapse(0.031, 60, 0.8, 0.6);
  ASSERT_GT(tall.aspect(), 2 * squat.aspect()) << "squat a = " << squat.aspect() << ", tall a = " << tall.aspect();
  EXPECT_GT(squat.normalised_runout(), 0.1) << "the squat column did not spread";
  EXPECT_GT(tall.normalised_runout(), squat.normalised_runout() * 1.5)
      << "squat: a = " << squat.aspect() << ", runout " << squat.normalised_runout() << "; tall: a = " << tall.aspect()
      << ", runout " << tall.normalised_runout();
  RecordProperty("squat", std::to_string(squat.aspect()) + " -> " + std::to_string(squat.normalised_runout()));
  RecordProperty("tall", std::to_string(tall.aspect()) + " -> " + std::to_string(tall.normalised_runout()));
}

}  // namespace
}  // namespace ts::sim
