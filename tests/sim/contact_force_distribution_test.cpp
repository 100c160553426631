// The small version of the contact-force run of docs/validation.md (thesis 7.2): a settled bed
// carries its weight on its floor, and its normal contact forces are spread broadly around their
// mean (force chains), not shared evenly.
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

TEST(ContactForces, SettledBedCarriesItsWeightOnBroadlySpreadNormalForces) {
  const Scene scene = load_scene(test::asset("scenes/reference/coarse_bed.toml"));
  World world = make_world(scene);
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, world, nullptr);
  CpuStepper stepper(world, settings);
  // Twice the scene's settling time, so the bed is at rest when its forces are read.
  const auto steps = static_cast<int>(std::ceil(2 * scene.simulation.duration / settings.dt));
  for (int s = 0; s < steps; ++s) stepper.step(world);
  const Energy e = energy(world);
  double weight = 0;  // N
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] == MotionType::Dynamic) weight += 9.81 / world.bodies.inverse_mass[b];
  }
  // At rest: the kinetic energy of every grain moving at 1 cm/s.
  ASSERT_LT(e.translational + e.rotational, 0.5 * (weight / 9.81) * 1e-4) << "the bed is not at rest";

  const std::vector<Eigen::Vector3d> x = particle_positions(world);
  double wall_lift = 0;  // N: upward force of the walls on the grains
  std::vector<double> normal;  // N, grain-grain contacts
  for (const ContactRecord& c : stepper.contacts(world)) {
    if (c.partner < 0) {
      wall_lift += c.force.z();
      continue;
    }
    const Eigen::Vector3d n = (x[c.particle] - x[static_cast<std::size_t>(c.partner)]).normalized();
    const double fn = c.force.dot(n);
    EXPECT_GT(fn, 0) << "a contact pulls its grains together";
    normal.push_back(std::abs(fn));
  }
  // At rest the walls carry the whole weight (grain-grain forces cancel in pairs).
  EXPECT_NEAR(wall_lift, weight, 0.02 * weight);

  ASSERT_GT(normal.size(), 200u);
  double mean = 0;
  for (double f : normal) mean += f;
  mean /= static_cast<double>(normal.size());
  double variance = 0;
  std::size_t above_two = 0;
  for (double f : normal) {
    variance += (f - mean) * (f - mean);
    above_two += f > 2 * mean ? 1 : 0;
  }
  const double cv = std::sqrt(variance / static_cast<double>(normal.size())) / mean;
  // An exponential distribution has CV 1 and e^-2 = 14 % above twice the mean; an even load
  // (every contact bearing its share) would have CV near 0 and nothing above 2.
  EXPECT_GT(cv, 0.4);
  EXPECT_LT(cv, 1.5);
  const double tail = static_cast<double>(above_two) / static_cast<double>(normal.size());
  EXPECT_GT(tail, 0.03);
  EXPECT_LT(tail, 0.30);
}

}  // namespace
}  // namespace ts::sim
