// Long runs of the GPU pipeline and the CPU reference agree statistically (issue 6): after the
// trajectories have diverged (float against double, chaotic collisions), the settled state's
// statistics must not. The larger version is the `agreement` run of bench/validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/atomic_file.h"
#include "gpu/context.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "tests/test_support.h"

namespace ts::sim {
using namespace ts::scene;  // these tests run whole scenes through the engine
namespace {

// Sorted heights (m) of the dynamic bodies' centres.
std::vector<double> heights(const World& world) {
  std::vector<double> z;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] == MotionType::Dynamic) z.push_back(world.bodies.position[b].z());
  }
  std::sort(z.begin(), z.end());
  return z;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double quantile(const std::vector<double>& sorted, double q) {
  return sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
}

double kinetic_energy(const World& world) {
  const Energy e = energy(world);
  return e.translational + e.rotational;
}

// Settles `scene` on both engines and compares the beds (the criteria of the monodisperse test).
void expect_settled_beds_agree(const Scene& scene) {
  World cpu_world = make_world(scene);
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, cpu_world, nullptr);
  const auto steps = static_cast<int>(std::ceil(scene.simulation.duration / settings.dt));
  World gpu_world = cpu_world;
  double lightest = 1e300, smallest = 1e300;  // kg, m
  for (std::size_t b = 0; b < cpu_world.bodies.size(); ++b)
    if (cpu_world.bodies.inverse_mass[b] > 0)
      lightest = std::min(lightest, 1.0 / cpu_world.bodies.inverse_mass[b]);
  for (double r : cpu_world.particles.radius) smallest = std::min(smallest, r);
  const double drop_scale = lightest * 9.81 * smallest;  // J: the lightest grain lifted by the smallest r

  CpuStepper cpu(cpu_world, settings);
  for (int s = 0; s < steps; ++s) cpu.step(cpu_world);
  gpu::Context context;
  GpuStepper gpu(context, gpu_world, settings, Precision::Float);
  gpu.step(steps);
  gpu.download(gpu_world);

  // Both beds at rest: less kinetic energy per grain than lifting it by a tenth of its radius.
  const double grains = static_cast<double>(cpu_world.bodies.size());
  EXPECT_LT(kinetic_energy(cpu_world) / grains, 0.1 * drop_scale);
  EXPECT_LT(kinetic_energy(gpu_world) / grains, 0.1 * drop_scale);
  // The grains did not follow the same paths (otherwise this would test determinism, not statistics).
  const double moved = (cpu_world.bodies.position.back() - gpu_world.bodies.position.back()).norm();
  ::testing::Test::RecordProperty("last_grain_apart_m", std::to_string(moved));
  // The bed's mean centre height within 3 % and its upper decile within 5 %. From one fill seed to the
  // next the CPU reference's 120-grain bed varies by 2.9 % (mean) and 4.6 % (upper decile), max - min
  // over seeds 1-4; the GPU run of the same seed differs by less than either (0.2 % and 0.9 % seen).
  const std::vector<double> zc = heights(cpu_world), zg = heights(gpu_world);
  ::testing::Test::RecordProperty("mean_height_cpu_m", std::to_string(mean(zc)));
  ::testing::Test::RecordProperty("mean_height_gpu_m", std::to_string(mean(zg)));
  ::testing::Test::RecordProperty("q90_height_cpu_m", std::to_string(quantile(zc, 0.9)));
  ::testing::Test::RecordProperty("q90_height_gpu_m", std::to_string(quantile(zg, 0.9)));
  EXPECT_NEAR(mean(zg) / mean(zc), 1.0, 0.03) << "mean centre height CPU " << mean(zc) << " m, GPU " << mean(zg);
  EXPECT_NEAR(quantile(zg, 0.9) / quantile(zc, 0.9), 1.0, 0.05)
      << "90th percentile CPU " << quantile(zc, 0.9) << " m, GPU " << quantile(zg, 0.9);
}

TEST(GpuCpuAgreement, SettledBedHeightAgreesWithinThePackingSpread) {
  expect_settled_beds_agree(load_scene(test::asset("scenes/reference/coarse_bed.toml")));
}

// The same bed polydisperse (issue 18): half 5 mm and half 3.5 mm grains, each scaled by a uniform
// 0.85-1.0, on the lattice of the monodisperse bed (its largest grain is the same).
TEST(GpuCpuAgreement, PolydisperseSettledBedHeightAgreesWithinThePackingSpread) {
  std::string text = read_file(test::asset("scenes/reference/coarse_bed.toml"));
  const std::string grain = "[grain]\nradius = 5.0e-3\nmaterial = \"sand\"\n";
  ASSERT_NE(text.find(grain), std::string::npos);
  text.replace(text.find(grain), grain.size(),
               "[[grain]]\nname = \"coarse\"\nradius = 5.0e-3\nmaterial = \"sand\"\n"
               "[[grain]]\nname = \"fine\"\nradius = 3.5e-3\nmaterial = \"sand\"\n");
  const std::string seed = "seed = 3\n";
  text.replace(text.find(seed), seed.size(),
               "seed = 3\ngrain = [\"coarse\", \"fine\"]\nfractions = [0.5, 0.5]\n"
               "size = { distribution = \"uniform\", min = 0.85, max = 1.0 }\n");
  const Scene scene = parse_scene(text, test::asset("scenes/reference/coarse_bed.toml"));
  ASSERT_EQ(make_world(scene).bodies.size(), 120u);
  expect_settled_beds_agree(scene);
}

}  // namespace
}  // namespace ts::sim
