// Contact candidate lists (sim/contact_lists.h) must never miss a contact: on a fast, chaotic scene
// every step's contacts, as each engine counts them, equal a brute-force search over all pairs of
// the state the step started from. An engine tests each candidate with the exact touching test, so
// its contacts are a subset of the touching pairs: equal counts mean equal sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <string>

#include "gpu/context.h"
#include "sim/contact_lists.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"
#include "sim/grain.h"
#include "sim/world.h"

namespace ts::sim {
namespace {

constexpr double kRadius = 1e-3;      // m, grain particles
constexpr double kBox = 0.024;        // m, side of the walled box
constexpr double kLaunchSpeed = 3.0;  // m/s, faster than the design speed handed to the engines

// Touching pairs and wall contacts of `world` as the engines count them (each pair once; at least
// one side dynamic; walls only for dynamic particles), with overlaps deeper than `margin` (m; < 0
// also counts pairs that miss by up to -margin).
struct ContactCount {
  std::size_t pairs = 0, walls = 0;
  std::size_t total() const { return pairs + walls; }
};

ContactCount brute_force_contacts(const World& world, double margin) {
  const std::vector<Eigen::Vector3d> x = particle_positions(world);
  const Particles& p = world.particles;
  auto dynamic = [&](std::size_t i) { return world.bodies.inverse_mass[p.body[i]] > 0; };
  ContactCount count;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      if (p.body[i] == p.body[j] || (!dynamic(i) && !dynamic(j))) continue;
      count.pairs += p.radius[i] + p.radius[j] - (x[i] - x[j]).norm() > margin ? 1 : 0;
    }
    if (!dynamic(i)) continue;
    for (const PlaneWall& wall : world.walls.planes) {
      count.walls += p.radius[i] - wall.normal.dot(x[i] - wall.point) > margin ? 1 : 0;
    }
    for (const CylinderWall& wall : world.walls.cylinders) {
      const double distance = (x[i].head<2>() - wall.axis).norm();
      if (x[i].z() < wall.z_min || x[i].z() > wall.z_max || distance <= 0) continue;
      count.walls += p.radius[i] - (wall.radius - distance) > margin ? 1 : 0;
    }
  }
  return count;
}

// A ring of `count` particles of radius `radius` (m) around the body's centre: a prop.
std::vector<Eigen::Vector3d> ring(int count, double radius) {
  std::vector<Eigen::Vector3d> offsets;
  const double ring_radius = count * radius / std::numbers::pi;  // neighbours touch
  for (int k = 0; k < count; ++k) {
    const double a = 2 * std::numbers::pi * k / count;
    offsets.emplace_back(ring_radius * std::cos(a), ring_radius * std::sin(a), 0.0);
  }
  return offsets;
}

// Grains flying in all directions at up to kLaunchSpeed inside a box of six planes and a cylinder,
// a heavy dynamic ring of larger particles thrown through them and a static ring they hit: every
// kind of contact, at impact speeds, with particles of two sizes.
World chaotic_box(std::uint64_t seed) {
  World world;
  Material sand;
  sand.youngs_modulus = 1e7;
  sand.restitution = 0.9;
  world.materials = {sand};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const GrainShape grain = make_tetrahedral_grain(kRadius, 2 * kRadius, sand.density);
  for (int n = 0; n < 120; ++n) {
    const Eigen::Vector3d centre = Eigen::Vector3d::Constant(kBox / 2) + 0.4 * kBox * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    add_grain(world, grain, 0, centre, q, kLaunchSpeed / std::sqrt(3.0) * Eigen::Vector3d(u(rng), u(rng), u(rng)),
              300.0 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  const double prop_radius = 1.5 * kRadius;
  const std::vector<Eigen::Vector3d> offsets = ring(16, prop_radius);
  const std::vector<double> radii(offsets.size(), prop_radius);
  BodyDesc thrown;
  thrown.position = Eigen::Vector3d(0.3, 0.5, 0.5) * kBox;
  thrown.linear_velocity = Eigen::Vector3d(kLaunchSpeed, 0.0, 0.0);
  thrown.angular_velocity = Eigen::Vector3d(0.0, 200.0, 0.0);
  const double mass = 16 * sand.density * 4.0 / 3.0 * std::numbers::pi * std::pow(prop_radius, 3);
  thrown.inverse_mass = 1.0 / mass;
  thrown.inverse_inertia = Eigen::Matrix3d::Identity() / (mass * 4e-5);
  add_body(world, thrown, offsets, radii, 0);
  BodyDesc fixed;
  fixed.position = Eigen::Vector3d(0.7, 0.5, 0.5) * kBox;
  fixed.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()));
  fixed.motion = MotionType::Static;
  add_body(world, fixed, offsets, radii, 0);
  for (int axis = 0; axis < 3; ++axis) {
    world.walls.planes.push_back(PlaneWall{Eigen::Vector3d::Zero(), Eigen::Vector3d::Unit(axis), 0});
    world.walls.planes.push_back(PlaneWall{Eigen::Vector3d::Constant(kBox), -Eigen::Vector3d::Unit(axis), 0});
  }
  world.walls.cylinders.push_back(CylinderWall{Eigen::Vector2d::Constant(kBox / 2), 0.49 * kBox, 0.0, kBox, 0});
  return world;
}

StepSettings chaotic_settings() {
  StepSettings s;
  s.dt = 1e-5;              // about 30 steps per contact at 3 m/s (E = 10 MPa, r = 1 mm)
  s.design_speed = 1.0;     // below the launch speed: the lists must follow what particles do
  s.check_energy = false;   // the restitution of 0.9 and the walls are all this scene is about
  s.check_penetration = false;
  return s;
}

// Steps `world` `steps` times, comparing each step's counted contacts with the brute force on the
// state before it. `margin` (m) allows for the engine's rounding of positions (float on the GPU).
// Returns the contacts seen, summed over the steps, and how far the fastest particle travelled.
struct RunSummary {
  std::size_t contacts = 0;
  double max_travel = 0;  // m, the largest distance any one particle went
};
RunSummary expect_every_contact_found(Stepper& stepper, World world, int steps, double margin) {
  stepper.load(world);
  RunSummary summary;
  std::vector<double> travelled(world.particles.size(), 0.0);
  for (int s = 0; s < steps; ++s) {
    const ContactCount deep = brute_force_contacts(world, margin);
    const ContactCount touching = brute_force_contacts(world, -margin);
    const std::vector<Eigen::Vector3d> before = particle_positions(world);
    const StepStats stats = stepper.advance(world, 1);
    const std::size_t found = stats.contacts + stats.wall_contacts;
    EXPECT_GE(found, deep.total()) << stepper.engine() << ": step " << s << " missed contacts (" << stats.contacts
                                   << " pairs + " << stats.wall_contacts << " walls; brute force " << deep.pairs
                                   << " + " << deep.walls << ")";
    EXPECT_LE(found, touching.total()) << stepper.engine() << ": step " << s << " counted pairs that do not touch";
    if (found < deep.total()) break;  // one report is enough
    summary.contacts += found;
    const std::vector<Eigen::Vector3d> after = particle_positions(world);
    for (std::size_t i = 0; i < after.size(); ++i) {
      travelled[i] += (after[i] - before[i]).norm();
      summary.max_travel = std::max(summary.max_travel, travelled[i]);
    }
  }
  return summary;
}

// The scene only tests the lists if particles outrun them many times and contacts abound.
void expect_a_demanding_run(const RunSummary& run, const World& world, const StepSettings& settings) {
  const double skin = choose_skin(2 * 1.5 * kRadius, settings.design_speed, settings.dt, settings.skin);
  EXPECT_GT(run.max_travel, 10 * skin) << "particles stayed within their lists' skin";
  EXPECT_GT(run.contacts, 5 * world.particles.size()) << "too few contacts to test";
}

TEST(ContactLists, CpuReferenceMissesNoContactInAFastChaoticScene) {
  const World world = chaotic_box(1);
  const StepSettings settings = chaotic_settings();
  CpuStepper stepper(settings);
  const RunSummary run = expect_every_contact_found(stepper, world, 400, 1e-12 * kRadius);
  expect_a_demanding_run(run, world, settings);
}

TEST(ContactLists, CpuReferenceMissesNoContactWithTheSmallestSkin) {
  // The skin at its floor (kMinSkinRatio of a diameter): lists are rebuilt every few steps.
  const World world = chaotic_box(2);
  StepSettings settings = chaotic_settings();
  settings.design_speed = 0;
  CpuStepper stepper(settings);
  const RunSummary run = expect_every_contact_found(stepper, world, 200, 1e-12 * kRadius);
  expect_a_demanding_run(run, world, settings);
}

class ContactListsGpu : public ::testing::Test {
 protected:
  gpu::Context context;
};

TEST_F(ContactListsGpu, GpuPipelineMissesNoContactInAFastChaoticSceneInBothPrecisions) {
  const World world = chaotic_box(3);
  const StepSettings settings = chaotic_settings();
  for (const Precision precision : {Precision::Float, Precision::Double}) {
    GpuStepper stepper(context, settings, precision);
    // Float positions are rounded to about 1e-7 of the box: a pair that touches by less may go
    // either way.
    const double margin = precision == Precision::Float ? 1e-4 * kRadius : 1e-9 * kRadius;
    const RunSummary run = expect_every_contact_found(stepper, world, 300, margin);
    expect_a_demanding_run(run, world, settings);
  }
}

TEST(ContactLists, SkinFollowsTheDesignSpeedWithinItsBounds) {
  const double d = 2e-3, dt = 1e-5;
  EXPECT_DOUBLE_EQ(choose_skin(d, 1.0, dt), 2 * 1.0 * dt * kStepsPerListBuild);
  EXPECT_DOUBLE_EQ(choose_skin(d, 0.0, dt), kMinSkinRatio * d);
  EXPECT_DOUBLE_EQ(choose_skin(d, 1e3, dt), kMaxSkinRatio * d);
  EXPECT_DOUBLE_EQ(choose_skin(d, 1e3, dt, 1e-4), 1e-4);
  EXPECT_DOUBLE_EQ(choose_skin(d, std::numeric_limits<double>::infinity(), dt), kMaxSkinRatio * d);
  EXPECT_TRUE(lists_need_rebuild(0.51e-4, 1e-4));
  EXPECT_FALSE(lists_need_rebuild(0.5e-4, 1e-4));
}

}  // namespace
}  // namespace ts::sim
