// The GPU pipeline's contact candidate lists (sim/contact_lists.h, sim/gpu_lists.cpp): kept for many
// steps, rebuilt when the GPU finds a particle has moved half the skin, and never missing a contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "sim/gpu_stepper.h"
#include "sim/grain.h"
#include "sim/world.h"

namespace ts::sim {
namespace {

// A fast, chaotic heap: grains thrown at each other at up to `speed` (m/s) and spinning, some of
// them fixed props, above a floor.
World thrown_grains(int count, double speed, std::uint64_t seed) {
  World world;
  Material sand;
  sand.youngs_modulus = 1e7;
  world.materials = {sand};
  const GrainShape grain = make_tetrahedral_grain(0.005, 0.01, sand.density);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double spacing = 1.6 * grain.bounding_radius;
  const int side = static_cast<int>(std::ceil(std::cbrt(count)));
  for (int n = 0; n < count; ++n) {
    const Eigen::Vector3d position(spacing * (n % side), spacing * ((n / side) % side),
                                   grain.bounding_radius + spacing * (n / (side * side)));
    const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    add_grain(world, grain, 0, position, q, speed * Eigen::Vector3d(u(rng), u(rng), u(rng)),
              200.0 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  for (std::size_t k = 0; k < world.bodies.size(); k += 9) {  // props: they stop grains, never move
    world.bodies.motion[k] = MotionType::Static;
    world.bodies.linear_velocity[k].setZero();
    world.bodies.angular_velocity[k].setZero();
  }
  world.walls.planes.push_back(PlaneWall{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0});
  return world;
}

StepSettings fast_step() {
  StepSettings s;
  s.dt = 2e-6;
  s.design_speed = 3.0;
  s.check_energy = false;  // props are fixed bodies hit at speed: no energy check to pass
  return s;
}

// Touching particle pairs of different bodies, at least one of them dynamic, by testing every pair.
std::size_t brute_force_contacts(const World& world) {
  const Particles& p = world.particles;
  std::vector<Eigen::Vector3d> x(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    x[i] = world.bodies.position[p.body[i]] + world.bodies.orientation[p.body[i]] * p.offset[i];
  std::size_t contacts = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      if (p.body[i] == p.body[j]) continue;
      if (world.bodies.motion[p.body[i]] != MotionType::Dynamic && world.bodies.motion[p.body[j]] != MotionType::Dynamic)
        continue;
      const double dist = (x[i] - x[j]).norm();
      if (dist > 0.0 && p.radius[i] + p.radius[j] - dist > 0.0) ++contacts;
    }
  }
  return contacts;
}

class GpuListsTest : public ::testing::Test {
 protected:
  gpu::Context context;
};

// Every step's contacts, counted by the GPU over its lists, are those a search of all pairs finds on
// the state it reached, while the lists were rebuilt only now and then (double precision: the GPU's
// positions are the CPU's up to the last bits).
TEST_F(GpuListsTest, EveryStepsContactsMatchABruteForceSearch) {
  World world = thrown_grains(64, 3.0, 11);
  GpuStepper gpu(context, world, fast_step(), Precision::Double);
  const int steps = 150;
  // A step's contacts are those of the state it starts from (advance() then moves `world` on).
  std::size_t touching = brute_force_contacts(world), most = 0;
  for (int s = 0; s < steps; ++s) {
    const StepStats stats = gpu.advance(world, 1);
    ASSERT_EQ(stats.contacts, touching) << "step " << s;
    most = std::max(most, touching);
    touching = brute_force_contacts(world);
  }
  const GpuStepper::ListStats lists = gpu.list_stats();
  EXPECT_GT(most, 10u);
  EXPECT_GT(lists.builds, 1u);
  EXPECT_LT(lists.builds, static_cast<std::uint64_t>(steps) / 3);
  std::printf("%llu list builds in %d steps, skin %.3g m, K = %u\n", static_cast<unsigned long long>(lists.builds),
              steps, lists.skin, lists.capacity);
}

World run(gpu::Context& context, const World& world, const StepSettings& settings, int steps,
          GpuStepper::ListStats* lists) {
  GpuStepper gpu(context, world, settings);
  gpu.step(steps);
  World out = world;
  gpu.download(out);
  gpu.statistics();
  if (lists) *lists = gpu.list_stats();
  return out;
}

// Forces are summed over the touching candidates in ascending GPU index, so lists kept for many
// steps, lists rebuilt every step (a skin of a nanometre) and lists that overflow their capacity (a
// skin of three diameters: the grid walk takes over) give the same bits.
TEST_F(GpuListsTest, KeptRebuiltAndOverflowingListsGiveTheSameBits) {
  const World world = thrown_grains(64, 3.0, 12);
  StepSettings kept = fast_step(), every = fast_step(), wide = fast_step();
  every.skin = 1e-9;
  const int steps = 120;
  GpuStepper::ListStats kept_lists, every_lists, wide_lists;
  const World a = run(context, world, kept, steps, &kept_lists);
  const World b = run(context, world, every, steps, &every_lists);
  wide.skin = 3.0 * (kept_lists.cell - kept_lists.skin);  // the cell is the largest diameter + skin
  const World c = run(context, world, wide, steps, &wide_lists);
  for (std::size_t k = 0; k < world.bodies.size(); ++k) {
    ASSERT_EQ(a.bodies.position[k], b.bodies.position[k]) << k;
    ASSERT_EQ(a.bodies.linear_velocity[k], b.bodies.linear_velocity[k]) << k;
    ASSERT_EQ(a.bodies.position[k], c.bodies.position[k]) << k;
    ASSERT_EQ(a.bodies.angular_velocity[k], c.bodies.angular_velocity[k]) << k;
  }
  EXPECT_LT(kept_lists.builds, static_cast<std::uint64_t>(steps) / 3);
  EXPECT_EQ(every_lists.builds, static_cast<std::uint64_t>(steps));
  EXPECT_GT(wide_lists.overflows, 0u);
  EXPECT_EQ(kept_lists.overflows, 0u);
}

// A checkpoint taken between two list builds resumes bit for bit: the lists are not saved, and the
// rebuild at restore finds the same touching partners in the same order.
TEST_F(GpuListsTest, AResumedCheckpointContinuesBitForBit) {
  const World world = thrown_grains(48, 3.0, 13);
  StepSettings settings = fast_step();
  settings.tangential = TangentialModel::Spring;
  settings.resort_every = 25;
  const World whole = run(context, world, settings, 90, nullptr);
  GpuStepper first(context, world, settings);
  first.step(37);
  const std::string state = first.save_state();
  GpuStepper second(context, settings);
  second.restore_state(world, state);
  second.step(53);
  World resumed = world;
  second.download(resumed);
  for (std::size_t k = 0; k < world.bodies.size(); ++k) {
    ASSERT_EQ(whole.bodies.position[k], resumed.bodies.position[k]) << k;
    ASSERT_EQ(whole.bodies.orientation[k].coeffs(), resumed.bodies.orientation[k].coeffs()) << k;
    ASSERT_EQ(whole.bodies.angular_velocity[k], resumed.bodies.angular_velocity[k]) << k;
  }
  EXPECT_EQ(whole.springs.partner, resumed.springs.partner);
}

}  // namespace
}  // namespace ts::sim
