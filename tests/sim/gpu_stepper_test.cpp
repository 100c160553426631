// The GPU pipeline against the CPU double-precision reference on the same World.
#include "sim/gpu_stepper.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "core/error.h"
#include "sim/cpu_reference.h"
#include "sim/grain.h"
#include "sim/world.h"

namespace ts::sim {
namespace {

// A loose heap of randomly oriented grains, some overlapping each other and the floor, all moving.
World jostling_grains(int count, std::uint64_t seed) {
  World world;
  Material sand;
  sand.youngs_modulus = 1e7;
  world.materials = {sand};
  const GrainShape grain = make_tetrahedral_grain(0.005, 0.01, sand.density);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double spacing = 1.5 * grain.bounding_radius;  // dense enough that many grains touch
  const int side = static_cast<int>(std::ceil(std::cbrt(count)));
  for (int n = 0; n < count; ++n) {
    const Eigen::Vector3d position(spacing * (n % side), spacing * ((n / side) % side),
                                   0.8 * grain.bounding_radius + spacing * (n / (side * side)));
    const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    add_grain(world, grain, 0, position + 0.1 * grain.particle_radius * Eigen::Vector3d(u(rng), u(rng), u(rng)), q,
              0.2 * Eigen::Vector3d(u(rng), u(rng), u(rng)), 5.0 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  world.walls.planes.push_back(PlaneWall{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0});
  return world;
}

StepSettings small_step() {
  StepSettings s;
  s.dt = 2e-6;
  return s;
}

class GpuStepperTest : public ::testing::Test {
 protected:
  gpu::Context context;
};

TEST_F(GpuStepperTest, OneStepForcesAgreeWithCpuReference) {
  for (Precision precision : {Precision::Float, Precision::Double}) {
    World world = jostling_grains(64, 3);
    World cpu_world = world;
    CpuStepper cpu(cpu_world, small_step());
    const StepStats cpu_stats = cpu.step(cpu_world);
    GpuStepper gpu(context, world, small_step(), precision);
    gpu.step(1);
    const StepStats gpu_stats = gpu.statistics();
    ASSERT_GT(cpu_stats.contacts, 20u);
    EXPECT_EQ(gpu_stats.contacts, cpu_stats.contacts);
    EXPECT_EQ(gpu_stats.wall_contacts, cpu_stats.wall_contacts);
    // Compare the bodies' velocity change, which is the per-body force sum.
    World gpu_world = world;
    gpu.download(gpu_world);
    double worst = 0.0, scale = 0.0;
    for (std::size_t k = 0; k < world.bodies.size(); ++k) {
      const Eigen::Vector3d dv_cpu = cpu_world.bodies.linear_velocity[k] - world.bodies.linear_velocity[k];
      const Eigen::Vector3d dv_gpu = gpu_world.bodies.linear_velocity[k] - world.bodies.linear_velocity[k];
      worst = std::max(worst, (dv_cpu - dv_gpu).norm());
      scale = std::max(scale, dv_cpu.norm());
    }
    EXPECT_LT(worst / scale, 1e-4) << (precision == Precision::Float ? "float" : "double");
  }
}

TEST_F(GpuStepperTest, TwoGrainCollisionTrajectoryAgrees) {
  World world;
  Material sand;
  world.materials = {sand};
  world.gravity = Eigen::Vector3d::Zero();
  const GrainShape grain = make_tetrahedral_grain(0.005, 0.01, sand.density);
  add_grain(world, grain, 0, {-0.014, 0, 0}, Eigen::Quaterniond::Identity(), {0.5, 0, 0});
  add_grain(world, grain, 0, {0.014, 0.002, 0}, Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())),
            {-0.5, 0, 0});
  StepSettings settings;
  settings.dt = 2e-6;
  World cpu_world = world;
  CpuStepper cpu(cpu_world, settings);
  GpuStepper gpu(context, world, settings, Precision::Double);
  const int steps = 15000;  // 30 ms: approach, contact, separation
  for (int s = 0; s < steps; ++s) cpu.step(cpu_world);
  gpu.step(steps);
  World gpu_world = world;
  gpu.download(gpu_world);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_LT((gpu_world.bodies.position[k] - cpu_world.bodies.position[k]).norm(), 1e-6) << k;
    EXPECT_LT((gpu_world.bodies.linear_velocity[k] - cpu_world.bodies.linear_velocity[k]).norm(), 1e-4) << k;
  }
  // They did collide: the x velocities reversed.
  EXPECT_LT(cpu_world.bodies.linear_velocity[0].x(), 0.0);
}

TEST_F(GpuStepperTest, TangentialSpringIsRefusedWithAClearMessage) {
  StepSettings settings = small_step();
  settings.tangential = TangentialModel::Spring;
  try {
    GpuStepper gpu(context, jostling_grains(8, 1), settings);
    FAIL() << "the GPU pipeline has no contact springs yet";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::BadInput);
    EXPECT_NE(std::string(e.what()).find("CPU reference only"), std::string::npos) << e.what();
  }
}

TEST_F(GpuStepperTest, SameSceneGivesBitwiseTheSameState) {
  const World world = jostling_grains(40, 9);
  std::vector<World> results;
  for (int run = 0; run < 2; ++run) {
    GpuStepper gpu(context, world, small_step());
    gpu.step(200);
    World out = world;
    gpu.download(out);
    results.push_back(out);
  }
  for (std::size_t k = 0; k < world.bodies.size(); ++k) {
    ASSERT_EQ(results[0].bodies.position[k], results[1].bodies.position[k]) << k;
    ASSERT_EQ(results[0].bodies.orientation[k].coeffs(), results[1].bodies.orientation[k].coeffs()) << k;
  }
}

TEST_F(GpuStepperTest, FreeFallMatchesAnalyticSolutionToTheChosenPrecision) {
  for (Precision precision : {Precision::Float, Precision::Double}) {
  World world;
  world.materials = {Material{}};
  const GrainShape grain = make_tetrahedral_grain(0.005, 0.01, 2600.0);
  add_grain(world, grain, 0, {0, 0, 1.0}, Eigen::Quaterniond::Identity(), {0.3, 0, 2.0});
  StepSettings settings;
  settings.dt = 1e-4;
  settings.integrator = Integrator::SemiImplicitEuler;
  GpuStepper gpu(context, world, settings, precision);
  const int steps = 3000;
  gpu.step(steps);
  World out = world;
  gpu.download(out);
  // Semi-implicit Euler under constant g: z_n = z0 + v0 t + g dt^2 n(n+1)/2, exactly.
  const double t = steps * settings.dt;
  const double z = 1.0 + 2.0 * t - 9.81 * settings.dt * settings.dt * steps * (steps + 1) / 2.0;
  // Each step rounds once per update: the bound is steps * machine epsilon * the largest magnitude (~2).
  const double epsilon = precision == Precision::Double ? std::numeric_limits<double>::epsilon()
                                                        : std::numeric_limits<float>::epsilon();
  const double tolerance = steps * epsilon * 2.0;
  EXPECT_NEAR(out.bodies.position[0].z(), z, tolerance);
  EXPECT_NEAR(out.bodies.position[0].x(), 0.3 * t, tolerance);
  EXPECT_NEAR(out.bodies.linear_velocity[0].z(), 2.0 - 9.81 * t, tolerance);
  }
}

}  // namespace
}  // namespace ts::sim
