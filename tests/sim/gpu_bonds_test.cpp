// Bonded spheres in the GPU pipeline (sim/gpu_bonds.cpp, shaders/sim/bond*.comp) against the CPU
// reference (sim/cpu_bonds.cpp): a bonded block thrown at a floor, breaking some of its bonds; the
// same run twice, and resumed from a checkpoint, bit for bit; bonded pairs kept out of the contacts.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "sim/cpu_bonds.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"
#include "sim/state_bytes.h"
#include "sim/world_bytes.h"
#include "tests/sim/bonded_worlds.h"

namespace ts::sim {
namespace {

using namespace ts::sim::bonded;

// A block of 32 bonded spheres falling at `speed` onto a floor of 169 static spheres, 50 um above it.
World thrown_block(double strength, double speed) {
  const double touch = 2.0 * kRadius + 1.5 * std::sqrt(2.0) * kRadius;  // centre height at first touch
  World w = bonded_block(2, cement(strength), V(0.1 * kRadius, -0.2 * kRadius, touch + 0.05 * kRadius));
  w.gravity = V(0, 0, -9.81);
  add_sphere_floor(w);
  for (std::size_t k = 0; k + 1 < w.bodies.size(); ++k) w.bodies.linear_velocity[k] = V(0.3 * speed, 0, -speed);
  return w;
}

StepSettings throw_settings(const World& w, double speed) {
  StepSettings s = symplectic(std::min(bond_step(w), 2e-7));
  s.design_speed = speed;
  s.resort_every = 50;  // re-sorts on the way: the bonds' spheres are renamed
  return s;
}

constexpr double kWeak = 2e4;   // Pa: breaks some bonds at 2 m/s (cpu_bonds_test.cpp: ~5e4 Pa at 1 m/s)
constexpr double kSpeed = 2.0;  // m/s
constexpr int kChunks = 60, kChunk = 20;  // 1200 steps: the fall, the impact and the rebound

class GpuBonds : public ::testing::Test {
 protected:
  gpu::Context context;
};

// The GPU pipeline breaks the same bonds in the same 20-step chunk as the CPU reference and keeps the
// spheres within the agreement tolerance of the other pipeline tests (1e-6 m, against 1 mm spheres),
// in both double pipelines; the bonds it reports broken are the ones whose flags it cleared.
TEST_F(GpuBonds, ThrownBlockBreaksTheSameBondsAsTheCpuReference) {
  for (Precision precision : {Precision::FullDouble, Precision::Double}) {
    World cpu_world = thrown_block(kWeak, kSpeed);
    World gpu_world = cpu_world;
    const StepSettings s = throw_settings(cpu_world, kSpeed);
    CpuStepper cpu(cpu_world, s);
    GpuStepper gpu(context, gpu_world, s, precision);
    std::size_t gpu_broken = 0, cpu_broken = 0, chunks_differing = 0;
    double worst = 0.0;
    for (int c = 0; c < kChunks; ++c) {
      cpu_broken += cpu.advance(cpu_world, kChunk).bonds_broken;
      gpu_broken += gpu.advance(gpu_world, kChunk).bonds_broken;
      chunks_differing += gpu_world.bonds.intact != cpu_world.bonds.intact ? 1 : 0;
      for (std::size_t k = 0; k < cpu_world.bodies.size(); ++k)
        worst = std::max(worst, (gpu_world.bodies.position[k] - cpu_world.bodies.position[k]).norm());
    }
    std::printf("%s: %zu of %zu bonds broken (CPU %zu), %zu chunks with other bonds intact, worst position "
                "difference %.3g m, dt %.3g s\n",
                gpu.engine().c_str(), gpu_broken, gpu_world.bonds.size(), cpu_broken, chunks_differing, worst, s.dt);
    EXPECT_GT(cpu_broken, 0u) << "the throw should break bonds";
    EXPECT_LT(cpu_broken, cpu_world.bonds.size()) << "and keep some";
    EXPECT_EQ(gpu_broken, gpu_world.bonds.size() - gpu_world.bonds.intact_count()) << gpu.engine();
    EXPECT_EQ(chunks_differing, 0u) << gpu.engine();
    EXPECT_LT(worst, 1e-6) << gpu.engine();
  }
}

// The bonds' elastic energy an output reports (reduced on the GPU) is the CPU reference's bond energy
// of the state the same output downloads, to the rounding of another summation order, in every
// pipeline; in the double pipelines it follows the CPU reference's own run within 1e-4 of the
// largest energy the bonds hold on the way (the float bond law of the mixed pipeline included).
TEST_F(GpuBonds, ReportedBondEnergyIsTheCpuReferencesEnergyOfTheSameState) {
  for (Precision precision : {Precision::FullDouble, Precision::Double, Precision::Float}) {
    World cpu_world = thrown_block(kWeak, kSpeed);
    World gpu_world = cpu_world;
    const StepSettings s = throw_settings(cpu_world, kSpeed);
    CpuStepper cpu(cpu_world, s);
    GpuStepper gpu(context, gpu_world, s, precision);
    double same_state = 0.0, against_cpu = 0.0, peak = 0.0;
    for (int c = 0; c < kChunks; ++c) {
      cpu.advance(cpu_world, kChunk);
      const double reported = gpu.advance(gpu_world, kChunk).elastic_energy;
      const double reference = bond_energy(gpu_world);
      same_state = std::max(same_state, std::abs(reported - reference) / std::max(reference, 1e-300));
      against_cpu = std::max(against_cpu, std::abs(reported - bond_energy(cpu_world)));
      peak = std::max(peak, reference);
    }
    std::printf("%s: bond energy up to %.3g J, reported vs the same state %.3g (relative), vs the CPU run %.3g J\n",
                gpu.engine().c_str(), peak, same_state, against_cpu);
    EXPECT_GT(peak, 0.0) << "the throw should load the bonds";
    EXPECT_LT(same_state, 1e-12) << gpu.engine();
    if (precision != Precision::Float) {
      EXPECT_LT(against_cpu, 1e-4 * peak) << gpu.engine();
    }
  }
}

// A block of more bonds than one work group of the energy reduction sums (256), shaken from the
// inside: the GPU's total over the groups' partials is still the CPU reference's energy of the state.
TEST_F(GpuBonds, BondEnergyOfManyWorkGroupsIsTheCpuReferencesEnergyOfTheSameState) {
  World w = bonded_block(4, cement());
  ASSERT_GT(w.bonds.size(), 4u * 256u) << "the test needs several work groups of bonds";
  for (std::size_t k = 0; k < w.bodies.size(); ++k) {
    const double x = static_cast<double>(k);
    w.bodies.linear_velocity[k] = 0.05 * V(std::sin(x), std::cos(1.7 * x), std::sin(0.3 * x + 1.0));
  }
  for (Precision precision : {Precision::FullDouble, Precision::Float}) {
    World run = w;
    GpuStepper gpu(context, run, symplectic(bond_step(w)), precision);
    const double reported = gpu.advance(run, 50).elastic_energy;
    const double reference = bond_energy(run);
    EXPECT_GT(reference, 0.0);
    EXPECT_LT(std::abs(reported - reference), 1e-12 * reference) << gpu.engine();
  }
}

// Two runs of one throw in the float pipeline end in the same bits, the reported bond energy
// included: the bonds' loads are summed per particle, and their energies over the bonds, in a fixed
// order, with no float atomics.
TEST_F(GpuBonds, SameThrowGivesBitwiseTheSameState) {
  std::string first;
  std::uint64_t first_energy = 0;
  for (int run = 0; run < 2; ++run) {
    World w = thrown_block(kWeak, kSpeed);
    GpuStepper gpu(context, w, throw_settings(w, kSpeed), Precision::Float);
    const StepStats stats = gpu.advance(w, kChunks * kChunk);
    EXPECT_EQ(stats.bonds_broken, w.bonds.size() - w.bonds.intact_count());
    EXPECT_GT(stats.bonds_broken, 0u);
    EXPECT_GT(stats.elastic_energy, 0.0);
    if (run == 0) {
      first = world_bytes(w);
      first_energy = std::bit_cast<std::uint64_t>(stats.elastic_energy);
    } else {
      EXPECT_TRUE(world_bytes(w) == first) << "the second run differs";
      EXPECT_EQ(std::bit_cast<std::uint64_t>(stats.elastic_energy), first_energy) << "its bond energy differs";
    }
  }
}

// A run saved half way (the world and the pipeline's state) and resumed by a new stepper ends in the
// same bits as the run that went straight on, bonds broken before and after the save included.
TEST_F(GpuBonds, ResumedThrowGoesOnBitForBit) {
  World w = thrown_block(kWeak, kSpeed);
  const StepSettings s = throw_settings(w, kSpeed);
  GpuStepper straight(context, w, s, Precision::Double);
  const std::int64_t half = kChunks * kChunk / 2;
  const std::size_t broken_before = straight.advance(w, half).bonds_broken;
  const std::string world_saved = world_bytes(w);
  const std::string engine_saved = straight.save_state();
  const std::size_t broken_after = straight.advance(w, half).bonds_broken;

  ByteReader reader(world_saved, "the saved world");
  World resumed = world_from_bytes(reader);
  GpuStepper again(context, s, Precision::Double);
  again.restore_state(resumed, engine_saved);
  EXPECT_EQ(again.advance(resumed, half).bonds_broken, broken_after);
  EXPECT_TRUE(world_bytes(resumed) == world_bytes(w)) << "the resumed run differs";
  EXPECT_TRUE(again.save_state() == straight.save_state());
  std::printf("resumed throw: %zu bonds broken before the save, %zu after\n", broken_before, broken_after);
  EXPECT_GT(broken_before + broken_after, 0u);
}

// Overlapping bonded spheres are no contacts (the lists leave them to their bonds); a pair whose bond
// breaks meets through the contact law from the next step.
TEST_F(GpuBonds, BondedSpheresAreNoContactsUntilTheirBondBreaks) {
  World w = bonded_block(1, cement());
  for (V& p : w.bodies.position) p *= 0.98;  // every bonded pair overlaps a little
  GpuStepper block(context, w, symplectic(1e-8), Precision::Float);
  EXPECT_EQ(block.advance(w, 1).contacts, 0u);

  World two = sliding_pair_bonded_weakly_in_shear(1.0 / w.bodies.inverse_mass[0]);
  ASSERT_EQ(two.bonds.size(), 1u);
  GpuStepper slide(context, two, symplectic(1e-8), Precision::Double);
  std::size_t broke = 0;
  for (int k = 0; k < 1000 && broke == 0; ++k) broke = slide.advance(two, 1).bonds_broken;
  ASSERT_EQ(broke, 1u);
  EXPECT_EQ(two.bonds.intact_count(), 0u);
  EXPECT_EQ(slide.advance(two, 1).contacts, 1u) << "the broken pair meets through the contact law";
}

// Spheres crowded past the list's capacity walk the grid instead (list_build.comp); their intact bonded
// partners, listed in their rows, are still no contacts there: one step agrees with the CPU reference
// on the contacts and on every body's velocity change.
TEST_F(GpuBonds, BondedSpheresWhoseListsOverflowStillSkipTheirBondedPartners) {
  World w = bonded_block(3, cement());
  for (V& p : w.bodies.position) p *= 0.6;  // bonds made touching, then crowded into each other
  World cpu_world = w;
  StepSettings s = symplectic(1e-10);
  s.check_energy = false;  // crowded this far, the overlaps are a test's, not a run's
  CpuStepper cpu(cpu_world, s);
  const StepStats cpu_stats = cpu.step(cpu_world);
  World gpu_world = w;
  GpuStepper gpu(context, gpu_world, s, Precision::Double);
  const StepStats gpu_stats = gpu.advance(gpu_world, 1);
  EXPECT_GT(gpu.list_stats().overflows, 0u) << "the test needs lists that overflow";
  ASSERT_GT(cpu_stats.contacts, 0u);
  EXPECT_EQ(gpu_stats.contacts, cpu_stats.contacts);
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < w.bodies.size(); ++k) {
    const V dv_cpu = cpu_world.bodies.linear_velocity[k] - w.bodies.linear_velocity[k];
    const V dv_gpu = gpu_world.bodies.linear_velocity[k] - w.bodies.linear_velocity[k];
    worst = std::max(worst, (dv_cpu - dv_gpu).norm());
    scale = std::max(scale, dv_cpu.norm());
  }
  EXPECT_LT(worst / scale, 1e-4);  // the float contact law of the mixed pipeline (GpuStepperTest's bound)
}

// The GPU twin of CpuBonds.BrokenOverlappingPairGainsNoEnergy: the contact kernel takes only the
// overlap beyond the broken bond's rest overlap.
TEST_F(GpuBonds, BrokenOverlappingPairGainsNoEnergy) {
  World w = overlapping_pair(0.05);
  const double before = energy(w).total();
  GpuStepper gpu(context, w, symplectic(1e-8), Precision::Double);
  std::size_t broke = 0;
  double most = before;
  for (int k = 0; k < 30; ++k) {
    broke += gpu.advance(w, 20).bonds_broken;
    most = std::max(most, energy(w).total());
  }
  ASSERT_EQ(broke, 1u);
  EXPECT_LE(most, before * (1.0 + 1e-9));
}

}  // namespace
}  // namespace ts::sim
