// Bonded spheres in the CPU reference (sim/cpu_bonds.h): criterion 2 of docs/validation.md "Bonded
// particles" for a whole body, bonds breaking into contacts and the bonds in checkpoints (the GPU
// pipeline's bonds: gpu_bonds_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "sim/cpu_bonds.h"
#include "sim/cpu_stepper.h"
#include "sim/state_bytes.h"
#include "sim/world_bytes.h"
#include "tests/sim/bonded_worlds.h"

namespace ts::sim {
namespace {

using namespace ts::sim::bonded;
// Kinetic energy with each body's mid-step velocities (the mean of the two half-step ones).
double mid_step_kinetic(const World& before, const World& after) {
  double e = 0;
  for (std::size_t k = 0; k < after.bodies.size(); ++k) {
    const double m = 1.0 / after.bodies.inverse_mass[k];
    const double inertia = 1.0 / after.bodies.inverse_inertia[k](0, 0);
    const V v = 0.5 * (before.bodies.linear_velocity[k] + after.bodies.linear_velocity[k]);
    const V w = 0.5 * (before.bodies.angular_velocity[k] + after.bodies.angular_velocity[k]);
    e += 0.5 * m * v.squaredNorm() + 0.5 * inertia * w.squaredNorm();
  }
  return e;
}

// Spins the block about its centre and shakes each sphere (up to `shake`, m/s), so every bond
// stretches, shears, twists and bends.
void launch(World& w, const V& spin, double shake) {
  for (std::size_t k = 0; k < w.bodies.size(); ++k) {
    const double wobble = shake * std::sin(1.7 * static_cast<double>(k));  // m/s
    w.bodies.linear_velocity[k] = spin.cross(w.bodies.position[k]) + V(wobble, -0.5 * wobble, 0.3 * wobble);
    w.bodies.angular_velocity[k] = spin;
  }
}

TEST(CpuBonds, UnbrokenBodyKeepsItsEnergyWithoutDampingOrContact) {
  World w = bonded_block(2, cement());
  launch(w, V(0.0, 0.0, 2.0), 1e-4);
  const double dt = bond_step(w);
  CpuStepper stepper(w, symplectic(dt));
  double first = 0, worst = 0;
  for (int k = 0; k < 10000; ++k) {
    const World before = w;
    const double held = bond_energy(w);  // at the step's start, where the loads are taken
    stepper.step(w);
    const double energy = mid_step_kinetic(before, w) + held;
    if (k == 0) first = energy;
    worst = std::max(worst, std::abs(energy / first - 1.0));
  }
  EXPECT_EQ(w.bonds.intact_count(), w.bonds.size());
  std::printf("bonded block: largest energy error %.3g over 10^4 steps at dt = %.3g s\n", worst, dt);
  EXPECT_LT(worst, 0.005) << "criterion 2: 0.5 % over 10^4 steps at the bonds' time step";
}

TEST(CpuBonds, StiffBondedBodyTurnsAsTheRigidBodyDoes) {
  BondMaterial stiff = cement();
  stiff.youngs_modulus = 100 * Material{}.youngs_modulus;  // criterion 2: 100x the contact modulus
  World w = bonded_block(2, stiff);
  const V spin(0.0, 0.0, 1000.0);  // rad/s: half a turn and more over the run
  for (std::size_t k = 0; k < w.bodies.size(); ++k) {
    w.bodies.linear_velocity[k] = spin.cross(w.bodies.position[k]);
    w.bodies.angular_velocity[k] = spin;
  }
  const std::vector<V> start = w.bodies.position;
  const double dt = bond_step(w);
  CpuStepper stepper(w, symplectic(dt));
  const int steps = 10000;
  stepper.advance(w, steps);
  const Eigen::AngleAxisd turn(spin.norm() * dt * steps, spin.normalized());
  double size = 0, worst = 0;
  for (std::size_t k = 0; k < start.size(); ++k) {
    size = std::max(size, start[k].norm());
    worst = std::max(worst, (w.bodies.position[k] - turn * start[k]).norm());
  }
  EXPECT_GT(spin.norm() * dt * steps, 0.5) << "the test must turn the block by a good angle";
  std::printf("stiff bonded block: largest departure from the rigid turn %.3g of its size\n", worst / size);
  EXPECT_LT(worst, 0.01 * size) << "criterion 2: within 1 % of the rigid rotation";
}

// A block thrown at a floor of static spheres: how many bonds break, and how deep the pieces go.
struct Throw {
  std::size_t broken = 0, bonds = 0;
  double max_overlap_ratio = 0;
};

Throw throw_at_floor(double strength, double speed) {
  World w = bonded_block(2, cement(strength), V(0, 0, 0.01));
  w.gravity = V(0, 0, -9.81);
  add_sphere_floor(w);
  for (std::size_t k = 0; k + 1 < w.bodies.size(); ++k) w.bodies.linear_velocity[k] = V(0, 0, -speed);
  StepSettings s = symplectic(std::min(bond_step(w), 2e-7));
  s.design_speed = speed;
  CpuStepper stepper(w, s);
  Throw out;
  out.bonds = w.bonds.size();
  const double fall = (0.01 - 4 * kRadius) / speed;  // s until the block reaches the floor
  const auto steps = static_cast<std::int64_t>(1.5 * fall / s.dt);
  for (std::int64_t k = 0; k < steps; ++k) {
    const StepStats stats = stepper.step(w);
    out.broken += stats.bonds_broken;
    out.max_overlap_ratio = std::max(out.max_overlap_ratio, stats.max_overlap_ratio);
  }
  EXPECT_EQ(out.broken, w.bonds.size() - w.bonds.intact_count());
  return out;
}

TEST(CpuBonds, StrongBondsHoldAnImpactThatBreaksWeakOnesIntoTouchingPieces) {
  const Throw strong = throw_at_floor(1e9, 1.0);
  EXPECT_EQ(strong.broken, 0u);
  const Throw weak = throw_at_floor(2e4, 1.0);  // Hertz at 1 m/s: about 5e4 Pa across a bond
  std::printf("thrown block: %zu of %zu bonds broken; largest overlap / r %.3g (strong: %.3g)\n", weak.broken,
              weak.bonds, weak.max_overlap_ratio, strong.max_overlap_ratio);
  EXPECT_GT(weak.broken, 0u);
  // The pieces still meet through the contact law once their bonds are gone. A lone sphere hitting the
  // floor at 1 m/s sinks about 0.1 r by Hertz; the block pressing with its whole mass goes deeper; a
  // piece passing through another (a contact left out) would go past r.
  EXPECT_LT(weak.max_overlap_ratio, 0.5);
}

TEST(CpuBonds, BondedSpheresTakeNoContactForceUntilTheirBondBreaks) {
  World w = bonded_block(1, cement());
  for (V& p : w.bodies.position) p *= 0.98;  // every bonded pair overlaps a little
  CpuStepper stepper(w, symplectic(1e-8));
  EXPECT_TRUE(stepper.contacts(w).empty());

  // Two touching spheres bonded weakly in shear, pressed together and slid past each other: once the
  // bond breaks in a step, the same stepper's next lists hold the pair as a contact.
  World two = sliding_pair_bonded_weakly_in_shear(1.0 / w.bodies.inverse_mass[0]);
  ASSERT_EQ(two.bonds.size(), 1u);
  CpuStepper slide(two, symplectic(1e-8));
  std::size_t broke = 0;
  for (int k = 0; k < 1000 && broke == 0; ++k) broke = slide.step(two).bonds_broken;
  ASSERT_EQ(broke, 1u);
  EXPECT_EQ(slide.step(two).contacts, 1u) << "the broken pair meets through the contact law";
}

// A pair bonded while overlapping, pulled apart until its bond breaks: the contact law then takes only
// the overlap beyond the bond's rest overlap, so the pair leaves with no more energy than it came with
// (at its full overlap the Hertz force would throw it apart; docs/validation.md "Bonded particles").
TEST(CpuBonds, BrokenOverlappingPairGainsNoEnergy) {
  World w = overlapping_pair(0.05);
  ASSERT_EQ(w.bonds.size(), 1u);
  EXPECT_NEAR(w.bonds.rest_overlap[0], 0.1 * kRadius, 1e-12);
  const double before = energy(w).total();
  CpuStepper stepper(w, symplectic(1e-8));
  std::size_t broke = 0;
  double most = before;
  for (int k = 0; k < 600; ++k) {
    broke += stepper.step(w).bonds_broken;
    most = std::max(most, energy(w).total());
  }
  ASSERT_EQ(broke, 1u);
  std::printf("broken overlapping pair: kinetic energy %.4g J before, at most %.4g J after\n", before, most);
  EXPECT_LE(most, before * (1.0 + 1e-9));
}

TEST(CpuBonds, ResumedRunWithBondsGoesOnBitForBit) {
  World w = bonded_block(2, cement(3e4), V(0, 0, 0));
  launch(w, V(50.0, -30.0, 80.0), 0.5);  // shaken hard enough to break some bonds
  const StepSettings s = symplectic(bond_step(w));
  CpuStepper straight(w, s);
  straight.advance(w, 300);
  const std::string world_saved = world_bytes(w);
  const std::string engine_saved = straight.save_state();
  straight.advance(w, 300);

  ByteReader reader(world_saved, "the saved world");
  World resumed = world_from_bytes(reader);
  CpuStepper again(s);
  again.restore_state(resumed, engine_saved);
  again.advance(resumed, 300);
  EXPECT_EQ(world_bytes(resumed), world_bytes(w));
  EXPECT_GT(w.bonds.size() - w.bonds.intact_count(), 0u) << "the run should break bonds on the way";
}

TEST(CpuBonds, DamagedBondsInASavedWorldAreRefused) {
  World w = bonded_block(1, cement());
  w.bonds.b[0] = static_cast<std::uint32_t>(w.particles.size());  // past the last sphere
  const std::string bytes = world_bytes(w);
  ByteReader reader(bytes, "the saved world");
  EXPECT_THROW(world_from_bytes(reader), std::exception);
}

}  // namespace
}  // namespace ts::sim
