// The GPU pipeline against the CPU double-precision reference on the same World.
#include "sim/gpu_stepper.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <random>

#include "core/error.h"

#include "sim/cpu_stepper.h"
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
  for (Precision precision : {Precision::Float, Precision::Double, Precision::FullDouble}) {
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
    EXPECT_LT(worst / scale, 1e-4) << gpu.engine();
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

// Two grains meeting head on at 1 m/s, 0.014 m either side of `centre`, rotated against each other.
World head_on_collision(const Eigen::Vector3d& centre) {
  World world;
  Material sand;
  world.materials = {sand};
  world.gravity = Eigen::Vector3d::Zero();
  const GrainShape grain = make_tetrahedral_grain(0.005, 0.01, sand.density);
  add_grain(world, grain, 0, centre + Eigen::Vector3d(-0.014, 0, 0), Eigen::Quaterniond::Identity(), {0.5, 0, 0});
  add_grain(world, grain, 0, centre + Eigen::Vector3d(0.014, 0.002, 0),
            Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())), {-0.5, 0, 0});
  return world;
}

struct CollisionError {
  double position = 0, velocity = 0;  // m, m/s: the larger grain's difference from the CPU reference
  double restitution = 0;             // separation / approach speed along x
};

CollisionError collision_against(const World& start, const World& cpu_end, const World& end) {
  CollisionError e;
  for (std::size_t k = 0; k < 2; ++k) {
    e.position = std::max(e.position, (end.bodies.position[k] - cpu_end.bodies.position[k]).norm());
    e.velocity = std::max(e.velocity, (end.bodies.linear_velocity[k] - cpu_end.bodies.linear_velocity[k]).norm());
  }
  const double approach = start.bodies.linear_velocity[0].x() - start.bodies.linear_velocity[1].x();
  e.restitution = (end.bodies.linear_velocity[1].x() - end.bodies.linear_velocity[0].x()) / approach;
  return e;
}

// `--precision double` is mixed (float contact arithmetic on positions and velocities differenced in
// double): 100 m from the origin, where a float position resolves only 8 um of a 10 um overlap, it
// meets the full-double tolerances of TwoGrainCollisionTrajectoryAgrees (1e-6 m, 1e-4 m/s) against
// the CPU reference, as the full-double pipeline does, and bounces with full double's restitution to 1e-3.
TEST_F(GpuStepperTest, MixedDoubleAgreesWithCpuReferenceAsTightlyAsFullDouble) {
  const World world = head_on_collision({100.0, -40.0, 7.0});
  StepSettings settings;
  settings.dt = 2e-6;
  settings.normal_damping = NormalDamping::Thesis;  // the other damping specialisation than the tests above
  const int steps = 15000;  // 30 ms: approach, contact, separation
  World cpu_world = world;
  CpuStepper cpu(cpu_world, settings);
  for (int s = 0; s < steps; ++s) cpu.step(cpu_world);
  CollisionError errors[2];
  const Precision precisions[2] = {Precision::Double, Precision::FullDouble};
  for (int p = 0; p < 2; ++p) {
    GpuStepper gpu(context, world, settings, precisions[p]);
    gpu.step(steps);
    World gpu_world = world;
    gpu.download(gpu_world);
    errors[p] = collision_against(world, cpu_world, gpu_world);
    EXPECT_LT(errors[p].position, 1e-6) << gpu.engine();
    EXPECT_LT(errors[p].velocity, 1e-4) << gpu.engine();
  }
  const CollisionError reference = collision_against(world, cpu_world, cpu_world);
  EXPECT_GT(reference.restitution, 0.1);  // they did collide and part
  EXPECT_LT(reference.restitution, 1.0);  // with damping
  EXPECT_NEAR(errors[0].restitution, errors[1].restitution, 1e-3);
  std::printf("against the CPU reference (e = %.6f): mixed %.3g m, %.3g m/s, e = %.6f; full double %.3g m, "
              "%.3g m/s, e = %.6f\n",
              reference.restitution, errors[0].position, errors[0].velocity, errors[0].restitution,
              errors[1].position, errors[1].velocity, errors[1].restitution);
}

// Largest difference of the bodies' velocity change between two steppers, relative to the largest change.
double relative_velocity_change_error(const World& before, const World& a, const World& b) {
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < before.bodies.size(); ++k) {
    const Eigen::Vector3d dv_a = a.bodies.linear_velocity[k] - before.bodies.linear_velocity[k];
    const Eigen::Vector3d dv_b = b.bodies.linear_velocity[k] - before.bodies.linear_velocity[k];
    worst = std::max(worst, (dv_a - dv_b).norm());
    scale = std::max(scale, dv_a.norm());
  }
  return worst / scale;
}

// Particle `i`'s springs by partner. The slots hold them in the order its contacts were visited,
// which the GPU's lists (ascending GPU index) and the CPU's grid sweep do not share: contacts find
// their spring by partner, so the order carries nothing.
std::map<std::int64_t, Eigen::Vector3d> springs_of(const ContactSprings& springs, std::size_t i) {
  std::map<std::int64_t, Eigen::Vector3d> out;
  for (std::size_t s = i * ContactSprings::kSlots; s < (i + 1) * ContactSprings::kSlots; ++s)
    if (springs.partner[s] != ContactSprings::kNoPartner) out[springs.partner[s]] = springs.displacement[s];
  return out;
}

// Each particle holds in `b` the springs it holds in `a`, partner for partner, each agreeing to
// `tolerance` relative to the largest spring. Returns the number of springs in use.
std::size_t expect_same_springs(const ContactSprings& a, const ContactSprings& b, double tolerance) {
  EXPECT_EQ(a.partner.size(), b.partner.size());
  double worst = 0.0, scale = 0.0;
  std::size_t used = 0;
  for (std::size_t i = 0; i < std::min(a.partner.size(), b.partner.size()) / ContactSprings::kSlots; ++i) {
    const auto sa = springs_of(a, i), sb = springs_of(b, i);
    EXPECT_EQ(sa.size(), sb.size()) << "particle " << i;
    for (const auto& [partner, displacement] : sa) {
      const auto found = sb.find(partner);
      EXPECT_NE(found, sb.end()) << "particle " << i << " partner " << partner;
      if (found == sb.end()) continue;
      ++used;
      worst = std::max(worst, (displacement - found->second).norm());
      scale = std::max(scale, displacement.norm());
    }
  }
  EXPECT_LT(worst, tolerance * scale);
  return used;
}

StepSettings spring_step() {
  StepSettings s = small_step();
  s.tangential = TangentialModel::Spring;
  return s;
}

// The spring model's history on the GPU: a heap whose contacts already carry springs (40 CPU steps),
// stepped once more by both. Forces and the advanced springs agree; contacts find their old springs
// by partner id (a lost history would shrink the tangential forces far beyond 1e-4).
TEST_F(GpuStepperTest, SpringForcesAndHistoryAgreeWithCpuReference) {
  World world = jostling_grains(64, 3);
  {
    CpuStepper warm_up(world, spring_step());
    for (int s = 0; s < 40; ++s) warm_up.step(world);
  }
  for (Precision precision : {Precision::Float, Precision::Double}) {
    World cpu_world = world;
    CpuStepper cpu(cpu_world, spring_step());
    const StepStats cpu_stats = cpu.step(cpu_world);
    GpuStepper gpu(context, world, spring_step(), precision);
    gpu.step(1);
    const StepStats gpu_stats = gpu.statistics();
    World gpu_world = world;
    gpu.download(gpu_world);
    const char* name = precision == Precision::Float ? "float" : "double";
    ASSERT_GT(cpu_stats.contacts, 20u);
    EXPECT_EQ(gpu_stats.contacts, cpu_stats.contacts) << name;
    EXPECT_EQ(gpu_stats.spring_overflows, cpu_stats.spring_overflows) << name;
    EXPECT_LT(relative_velocity_change_error(world, cpu_world, gpu_world), 1e-4) << name;
    const std::size_t used = expect_same_springs(cpu_world.springs, gpu_world.springs, 1e-4);
    EXPECT_GT(used, 2 * cpu_stats.contacts);  // each pair holds two springs, plus the floor's
  }
}

// A grain sliding and spinning on the floor while resting on it: 3000 steps (6 ms) of contacts that
// slip, then stick, CPU reference against the GPU. Full double agrees to 1e-7 relative (measured
// 8e-9); mixed double (float force law) too on the trajectory, but its springs, cut back to mu F_n / k_t
// while sliding, carry the float normal force's rounding (measured 1.5e-7: allowed 5e-7); float to
// 3e-3 (measured 1.1e-3 on the spin): a float position near 7 mm resolves the 2 um overlap to 2e-4,
// and that error feeds the spring every step.
TEST_F(GpuStepperTest, SlidingSpringContactTrajectoryAgrees) {
  World world;
  Material sand;
  world.materials = {sand};
  const GrainShape grain = make_tetrahedral_grain(0.005, 0.01, sand.density);
  const Eigen::Quaterniond up = Eigen::Quaterniond::FromTwoVectors(grain.offsets[0], Eigen::Vector3d::UnitZ());
  const double base = -(up * grain.offsets[1]).z();
  add_grain(world, grain, 0, {0, 0, base + 0.005 - 2e-6}, up, {0.05, 0.02, 0}, {0, 0, 3.0});
  world.walls.planes.push_back(PlaneWall{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0});
  StepSettings settings = spring_step();
  World cpu_world = world;
  CpuStepper cpu(cpu_world, settings);
  const int steps = 3000;
  for (int s = 0; s < steps; ++s) cpu.step(cpu_world);
  EXPECT_EQ(cpu_world.springs.partner[ContactSprings::kSlots], -1);  // sphere 1 (a lower one) still on the floor
  const double moved = (cpu_world.bodies.position[0] - world.bodies.position[0]).head<2>().norm();
  EXPECT_GT(moved, 1e-4);  // m: it did slide
  for (Precision precision : {Precision::FullDouble, Precision::Double, Precision::Float}) {
    GpuStepper gpu(context, world, settings, precision);
    gpu.step(steps);
    World gpu_world = world;
    gpu.download(gpu_world);
    const double tolerance = precision == Precision::Float ? 3e-3 : 1e-7;  // relative
    const std::string name = gpu.engine();
    EXPECT_LT((gpu_world.bodies.position[0] - cpu_world.bodies.position[0]).norm(), tolerance * moved) << name;
    EXPECT_LT((gpu_world.bodies.linear_velocity[0] - cpu_world.bodies.linear_velocity[0]).norm(),
              tolerance * world.bodies.linear_velocity[0].norm()) << name;
    EXPECT_LT((gpu_world.bodies.angular_velocity[0] - cpu_world.bodies.angular_velocity[0]).norm(),
              tolerance * world.bodies.angular_velocity[0].norm()) << name;
    expect_same_springs(cpu_world.springs, gpu_world.springs, precision == Precision::Double ? 5e-7 : tolerance);
  }
}

// A grain standing on three spheres on a smooth plane tilted 20 degrees (tan 20 = 0.36 < mu = 0.5),
// stepped on the GPU: 20 ms for the contacts to load, then how far it moves down the slope in the
// next 0.05 s, in sphere radii (the CPU twin is in cpu_stepper_test.cpp).
double gpu_slide_on_incline(gpu::Context& context, TangentialModel tangential) {
  World w;
  w.materials = {Material{}};
  const double angle = 20.0 * std::numbers::pi / 180.0;
  w.gravity = 9.81 * Eigen::Vector3d(std::sin(angle), 0, -std::cos(angle));
  w.walls.planes.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0});
  const double r = 0.005;
  const GrainShape g = make_tetrahedral_grain(r, 2 * r, 2600);
  const Eigen::Quaterniond up = Eigen::Quaterniond::FromTwoVectors(g.offsets[0], Eigen::Vector3d::UnitZ());
  add_grain(w, g, 0, Eigen::Vector3d(0, 0, -(up * g.offsets[1]).z() + r - 1e-6), up);
  StepSettings s;
  s.dt = 1e-5;
  s.tangential = tangential;
  GpuStepper gpu(context, w, s);
  gpu.step(2000);
  World loaded = w;
  gpu.download(loaded);
  gpu.step(5000);
  EXPECT_EQ(gpu.statistics().wall_contacts, 3u);
  World later = w;
  gpu.download(later);
  return (later.bodies.position[0].x() - loaded.bodies.position[0].x()) / r;
}

// Thesis figure 2.8 in its smallest form, on the GPU: static friction (the spring) holds a grain on a
// slope below the friction angle; the viscous law of eq. 3.28 lets it creep at F_t / gamma_s.
// (A settled 300-grain heap: on the CPU reference in granular_physics_test.cpp; on the GPU, five
// minutes on llvmpipe, in bench/sim_spring_creep.py.)
TEST_F(GpuStepperTest, StaticFrictionHoldsAGrainOnAnInclineWhereViscousFrictionCreeps) {
  const double held = gpu_slide_on_incline(context, TangentialModel::Spring);
  const double crept = gpu_slide_on_incline(context, TangentialModel::Viscous);
  EXPECT_LT(std::abs(held), 1e-4) << "radii in 0.05 s";
  EXPECT_GT(crept, 100 * std::abs(held)) << "radii in 0.05 s";
  EXPECT_GT(crept, 5e-3) << "radii in 0.05 s";
  std::printf("moved down the slope in 0.05 s: %.3g radii with springs, %.3g viscous\n", held, crept);
}

TEST_F(GpuStepperTest, SameSceneGivesBitwiseTheSameState) {
  const World world = jostling_grains(40, 9);
  for (Precision precision : {Precision::Float, Precision::Double}) {
    std::vector<World> results;
    for (int run = 0; run < 2; ++run) {
      GpuStepper gpu(context, world, spring_step(), precision);
      gpu.step(200);
      World out = world;
      gpu.download(out);
      results.push_back(out);
    }
    for (std::size_t k = 0; k < world.bodies.size(); ++k) {
      ASSERT_EQ(results[0].bodies.position[k], results[1].bodies.position[k]) << k;
      ASSERT_EQ(results[0].bodies.orientation[k].coeffs(), results[1].bodies.orientation[k].coeffs()) << k;
    }
    EXPECT_EQ(results[0].springs.partner, results[1].springs.partner);
    EXPECT_EQ(results[0].springs.displacement, results[1].springs.displacement);
  }
}

// The scene-wide switches are compiled into the contact kernel (TS_CONTACT_*): a world is given the
// program of its combination, linked once per context and then taken from the program cache.
TEST_F(GpuStepperTest, ContactKernelIsLinkedOncePerCombinationOfSceneSwitches) {
  const World walls = jostling_grains(8, 1);  // on a floor
  World no_walls = walls;
  no_walls.walls.planes.clear();
  { GpuStepper first(context, walls, small_step()); }
  const std::size_t before = gpu::program_links();
  GpuStepper gpu(context, walls, small_step());
  EXPECT_EQ(gpu::program_links(), before);  // the same combination: every kernel from the cache
  gpu.load(no_walls);
  EXPECT_EQ(gpu::program_links(), before + 1);  // the kernel without wall loops
  gpu.load(walls);
  EXPECT_EQ(gpu::program_links(), before + 1);
  gpu.step(1);
  EXPECT_GT(gpu.statistics().wall_contacts, 0u);  // the wall variant again, and it sees the floor
}

// Periodic re-sorting by cell moves bodies and particles in GPU memory, never in the world: a heap
// re-sorted every 7 steps ends where the same heap never re-sorted does, up to the order of float sums
// in the gathers, runs bitwise the same twice, and keeps its springs' partners. (Measured with the
// contact lists, which sum partners in ascending GPU index, so a re-sort reorders sums: 0 m in
// position, 6e-8 m/s in velocity against 2.1 m/s.)
TEST_F(GpuStepperTest, ResortingKeepsResultsAndDeterminism) {
  World world = jostling_grains(60, 5);
  StepSettings plain = spring_step(), sorted = spring_step();
  plain.resort_every = 0;
  sorted.resort_every = 7;
  const int steps = 60;
  auto run = [&](const StepSettings& settings, std::vector<std::uint32_t>* order) {
    GpuStepper gpu(context, world, settings);
    gpu.step(steps);
    if (order) *order = gpu.body_order();
    World out = world;
    gpu.download(out);
    return out;
  };
  std::vector<std::uint32_t> order;
  const World a = run(plain, nullptr), b = run(sorted, &order), c = run(sorted, nullptr);
  std::size_t moved = 0;
  for (std::size_t k = 0; k < order.size(); ++k) moved += order[k] != k ? 1 : 0;
  EXPECT_GT(moved, order.size() / 2) << "the re-sort left the lattice order nearly unchanged";
  double worst_position = 0.0, worst_velocity = 0.0, speed = 0.0;
  for (std::size_t k = 0; k < world.bodies.size(); ++k) {
    ASSERT_EQ(b.bodies.position[k], c.bodies.position[k]) << k;  // deterministic
    ASSERT_EQ(b.bodies.orientation[k].coeffs(), c.bodies.orientation[k].coeffs()) << k;
    worst_position = std::max(worst_position, (a.bodies.position[k] - b.bodies.position[k]).norm());
    worst_velocity = std::max(worst_velocity, (a.bodies.linear_velocity[k] - b.bodies.linear_velocity[k]).norm());
    speed = std::max(speed, a.bodies.linear_velocity[k].norm());
  }
  EXPECT_LT(worst_position, 1e-7);  // m, against 5 mm spheres
  EXPECT_LT(worst_velocity, 1e-4 * speed);
  EXPECT_EQ(b.springs.partner, c.springs.partner);
  std::size_t same = 0, used = 0;
  for (std::size_t i = 0; i < a.springs.partner.size() / ContactSprings::kSlots; ++i) {
    const auto sa = springs_of(a.springs, i), sb = springs_of(b.springs, i);
    used += sa.size();
    for (const auto& entry : sa) same += sb.count(entry.first);
    EXPECT_EQ(sa.size(), sb.size()) << "particle " << i;
  }
  EXPECT_GT(used, 50u);
  EXPECT_EQ(same, used);  // the same partners, renamed back to world ids (slot order follows the visits)
  std::printf("re-sorted vs not after %d steps: %.3g m position, %.3g m/s velocity (largest speed %.3g m/s)\n",
              steps, worst_position, worst_velocity, speed);
}

// One step right after a re-sort: the per-particle forces, returned in world order, are those of
// the unsorted run up to float reassociation.
TEST_F(GpuStepperTest, ForcesAfterAResortAgreeWithTheUnsortedOrder) {
  const World world = jostling_grains(60, 5);
  StepSettings plain = small_step(), sorted = small_step();
  plain.resort_every = 0;
  sorted.resort_every = 1;  // re-sorts before the second step
  GpuStepper a(context, world, plain), b(context, world, sorted);
  a.step(2);
  b.step(2);
  const auto fa = a.particle_forces(), fb = b.particle_forces();
  double worst = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < fa.size(); ++i) {
    worst = std::max(worst, (fa[i] - fb[i]).norm());
    scale = std::max(scale, fa[i].norm());
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(worst, 1e-5 * scale);
}

// Between two outputs the steps run on the GPU alone: no buffer read, finish or timer read, also
// across a re-sort and with --timings' queries in flight (more than the 256 after which timers were
// once read mid-run); the outputs read back, and the timers are read once, at the end.
TEST_F(GpuStepperTest, StepsBetweenOutputsMakeNoHostRoundTrip) {
  World world = jostling_grains(8, 4);
  StepSettings settings = spring_step();
  settings.resort_every = 7;
  GpuStepper gpu(context, world, settings, Precision::Float, /*timings=*/true);
  gpu.advance(world, 3);
  const gpu::HostSyncCounts before = gpu::host_sync_counts();
  gpu.step(30);
  EXPECT_EQ((gpu::host_sync_counts() - before).total(), 0);
  gpu.advance(world, 30);
  const std::vector<gpu::HostSyncPhase> phases = gpu.round_trips();
  ASSERT_EQ(phases.size(), 3u);
  EXPECT_EQ(phases[0].units, 63);
  EXPECT_EQ(phases[0].counts.total(), 0);
  EXPECT_EQ(phases[1].units, 2);
  EXPECT_EQ(phases[1].counts.reads, 2 * (7 + 3));  // state with springs, statistics (docs/architecture.md)
  EXPECT_EQ(phases[1].counts.query_reads, 0);
  EXPECT_EQ(phases[2].counts.query_reads, 0);
  const std::string report = gpu.timing_report();
  EXPECT_NE(report.find("sim/contact_forces.comp"), std::string::npos) << report;
  EXPECT_NE(report.find("sim steps between outputs (63)"), std::string::npos) << report;
  EXPECT_EQ(gpu.round_trips()[2].counts.query_reads, 1) << report;
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
