// The CPU reference's contact candidate lists (sim/cpu_lists.h): complete while reused, rebuilt at half
// the skin, sorted by partner id, and results that do not depend on when they were built.
#include "sim/cpu_lists.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "sim/cpu_stepper.h"
#include "sim/grain.h"

namespace ts::sim {
namespace {

constexpr double kRadius = 1e-3;   // m, of a grain's particles
constexpr double kHalfBox = 1e-2;  // m

// 64 tetrahedral grains flying at up to `speed` (m/s) in random directions inside a closed box,
// with a kinematic paddle (one large particle) sweeping through them: impacts, rotation, walls.
World chaotic_box(double speed) {
  World w;
  w.materials.push_back(Material{});
  w.gravity = Eigen::Vector3d(0, 0, -9.81);
  for (int axis = 0; axis < 3; ++axis) {
    for (const double side : {-1.0, 1.0}) {
      const Eigen::Vector3d normal = -side * Eigen::Vector3d::Unit(axis);
      w.walls.planes.push_back({side * kHalfBox * Eigen::Vector3d::Unit(axis), normal, 0});
    }
  }
  const GrainShape g = make_tetrahedral_grain(kRadius, 2 * kRadius, 2600);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const double spacing = 4.6 * kRadius;  // m: apart (a grain reaches 2.2 radii from its centre)
  for (double z = -kHalfBox + 2 * kRadius; z < kHalfBox - 2 * kRadius; z += spacing) {
    for (double y = -kHalfBox + 2 * kRadius; y < kHalfBox - 2 * kRadius; y += spacing) {
      for (double x = -kHalfBox + 2 * kRadius; x < kHalfBox - 2 * kRadius; x += spacing) {
        const std::uint32_t k = add_grain(w, g, 0, Eigen::Vector3d(x, y, z),
                                          Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized());
        w.bodies.linear_velocity[k] = speed * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
        w.bodies.angular_velocity[k] = 200 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      }
    }
  }
  BodyDesc paddle;
  paddle.position = Eigen::Vector3d(0, 1e-3, -kHalfBox - 3e-3);
  paddle.linear_velocity = Eigen::Vector3d(0, 0, speed);
  paddle.motion = MotionType::Kinematic;
  add_body(w, paddle, {Eigen::Vector3d::Zero()}, {2.5 * kRadius}, 0);
  return w;
}

struct Counts {
  std::size_t pairs = 0, walls = 0;
};

// Every touching pair and particle-wall contact of `w`, by trying all pairs: the rules of
// sim/cpu_contacts.cpp (other bodies only, at least one side able to take a force; walls for those
// that can).
Counts brute_force_contacts(const World& w) {
  const std::vector<Eigen::Vector3d> x = particle_positions(w);
  const Particles& p = w.particles;
  auto takes_force = [&](std::size_t i) { return w.bodies.inverse_mass[p.body[i]] > 0; };
  Counts out;
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (std::size_t j = i + 1; j < x.size(); ++j) {
      if (p.body[i] == p.body[j] || (!takes_force(i) && !takes_force(j))) continue;
      const double reach = p.radius[i] + p.radius[j];
      out.pairs += (x[i] - x[j]).squaredNorm() < reach * reach ? 1 : 0;
    }
    if (!takes_force(i)) continue;
    for (const PlaneWall& wall : w.walls.planes)
      out.walls += wall.normal.dot(x[i] - wall.point) < p.radius[i] ? 1 : 0;
  }
  return out;
}

StepSettings chaotic_settings(double skin) {
  StepSettings s;
  s.dt = 2e-6;
  s.skin = skin;
  s.check_energy = false;  // the paddle does work
  return s;
}

TEST(CpuContactLists, StayCompleteWhileReusedOverManySteps) {
  World w = chaotic_box(3.0);
  // A large skin: each list serves many steps, so a missed partner would show.
  CpuStepper stepper(w, chaotic_settings(0.5 * 2 * kRadius));
  const int steps = 1500;
  std::size_t touching = 0;
  for (int i = 0; i < steps; ++i) {
    const Counts expected = brute_force_contacts(w);
    const StepStats stats = stepper.step(w);
    ASSERT_EQ(stats.contacts, expected.pairs) << "step " << i;
    ASSERT_EQ(stats.wall_contacts, expected.walls) << "step " << i;
    touching += expected.pairs;
  }
  EXPECT_GT(touching, std::size_t{steps});                       // the scene has contacts to find
  EXPECT_GE(stepper.lists().builds(), 3u);                       // lists were rebuilt as grains flew ...
  EXPECT_LE(stepper.lists().builds(), std::size_t{steps / 10});  // ... and each served many steps
}

TEST(CpuContactLists, RebuildOnlyOnceAParticleHasMovedMoreThanHalfTheSkin) {
  World w;
  w.materials.push_back(Material{});
  BodyDesc d;
  d.inverse_mass = 1;
  d.inverse_inertia = Eigen::Matrix3d::Identity();
  for (int k = 0; k < 4; ++k) {
    d.position = Eigen::Vector3d(3 * kRadius * k, 0, 0);
    add_body(w, d, {Eigen::Vector3d::Zero()}, {kRadius}, 0);
  }
  StepSettings s;
  s.skin = 1e-4;  // m
  CpuContactLists lists;
  std::vector<Eigen::Vector3d> x = particle_positions(w);
  EXPECT_TRUE(lists.stale(x));  // never built
  lists.build(w, x, s);
  EXPECT_DOUBLE_EQ(lists.skin(), s.skin);
  EXPECT_FALSE(lists.stale(x));
  x[2].y() += 0.49 * s.skin;
  EXPECT_FALSE(lists.stale(x));
  x[2].y() += 0.02 * s.skin;  // 0.51 of the skin from where it was built
  EXPECT_TRUE(lists.stale(x));
  x.pop_back();
  x[2] = particle_positions(w)[2];
  EXPECT_TRUE(lists.stale(x));  // another particle count
  lists.build(w, particle_positions(w), s);
  lists.invalidate();
  EXPECT_TRUE(lists.stale(particle_positions(w)));
}

TEST(CpuContactLists, ListsAreSortedByPartnerIdAndPointAtTheirCellOrderSlots) {
  const World w = chaotic_box(1.0);
  CpuContactLists lists;
  StepSettings s;
  s.skin = 2 * kRadius;  // wide enough to reach the neighbouring grains of the lattice
  lists.build(w, particle_positions(w), s);
  const auto& order = lists.order();
  std::size_t listed = 0;
  for (std::uint32_t slot = 0; slot < order.size(); ++slot) {
    ASSERT_EQ(lists.slot(order[slot]), slot);
    const auto list = lists.candidates(slot);
    listed += list.empty() ? 0 : 1;
    for (std::size_t k = 0; k < list.size(); ++k) {
      ASSERT_EQ(order[list[k].slot], list[k].particle);
      if (k > 0) {
        ASSERT_LT(list[k - 1].particle, list[k].particle);
      }
    }
  }
  EXPECT_GT(listed, order.size() / 2);
}

// The half lists: every candidate pair once, its first particle the side that counts the contact
// (the lower id of two that take a force, else the one that does), and both sides' entries naming it.
TEST(CpuContactLists, EachCandidatePairIsListedOnceAndBothSidesPointAtIt) {
  const World w = chaotic_box(1.0);  // with a kinematic paddle: pairs with one side that takes no force
  CpuContactLists lists;
  StepSettings s;
  s.skin = 2 * kRadius;
  lists.build(w, particle_positions(w), s);
  const auto& order = lists.order();
  const CandidatePairs& pairs = lists.pairs();
  auto takes_force = [&](std::uint32_t id) { return w.bodies.inverse_mass[w.particles.body[id]] != 0; };
  std::vector<int> entries_naming(pairs.size(), 0);
  std::size_t entries = 0, one_sided = 0;
  for (std::uint32_t slot = 0; slot < order.size(); ++slot) {
    for (const ListEntry& e : lists.candidates(slot)) {
      ++entries;
      ASSERT_LT(e.pair, pairs.size());
      ++entries_naming[e.pair];
      const std::uint32_t self = order[slot];
      const bool counts_here = !takes_force(e.particle) || self < e.particle;
      ASSERT_EQ(e.first, counts_here);
      ASSERT_EQ(e.first ? pairs.first[e.pair] : pairs.second[e.pair], slot);
      ASSERT_EQ(e.first ? pairs.second[e.pair] : pairs.first[e.pair], e.slot);
      one_sided += takes_force(e.particle) ? 0 : 1;
    }
  }
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const bool both_take_force = takes_force(order[pairs.first[p]]) && takes_force(order[pairs.second[p]]);
    ASSERT_EQ(entries_naming[p], both_take_force ? 2 : 1) << "pair " << p;
  }
  EXPECT_EQ(2 * pairs.size() - one_sided, entries);
  EXPECT_GT(pairs.size(), order.size());
}

// The same run with lists built at other steps (another skin; a stepper restored mid-run, which
// rebuilds at its first step) gives the same bits: forces are summed by partner id, not list order.
TEST(CpuReference, ResultsDoNotDependOnWhenTheListsWereBuilt) {
  for (const TangentialModel tangential : {TangentialModel::Viscous, TangentialModel::Spring}) {
    auto run = [&](double skin, int restore_at) {
      World w = chaotic_box(2.0);
      StepSettings s = chaotic_settings(skin);
      s.tangential = tangential;
      auto stepper = std::make_unique<CpuStepper>(w, s);
      for (int i = 0; i < 600; ++i) {
        if (i == restore_at) {
          const std::string state = stepper->save_state();
          stepper = std::make_unique<CpuStepper>(s);
          stepper->load(w);
          stepper->restore_state(w, state);
        }
        stepper->step(w);
      }
      return std::pair{w, stepper->lists().builds()};
    };
    const auto [a, builds_a] = run(0.1 * kRadius, -1);
    const auto [b, builds_b] = run(0.8 * kRadius, -1);
    const auto [c, builds_c] = run(0.1 * kRadius, 301);
    EXPECT_GT(builds_a, builds_b);  // the skins did change when the lists were built
    EXPECT_GT(builds_c, 0u);
    for (const World* other : {&b, &c}) {
      for (std::size_t k = 0; k < a.bodies.size(); ++k) {
        ASSERT_EQ(a.bodies.position[k], other->bodies.position[k]) << "body " << k;
        ASSERT_EQ(a.bodies.angular_velocity[k], other->bodies.angular_velocity[k]) << "body " << k;
      }
      ASSERT_EQ(a.springs.partner, other->springs.partner);
    }
  }
}

TEST(CpuReference, TimingReportStatesTheSkinAndTheListBuilds) {
  World w = chaotic_box(1.0);
  CpuStepper stepper(w, chaotic_settings(0.2 * kRadius));
  for (int i = 0; i < 20; ++i) stepper.step(w);
  const std::string report = stepper.timing_report();
  // 0.2 mm against the paddle's 5 mm diameter.
  EXPECT_NE(report.find("skin 0.0002 m (0.04 of the largest diameter"), std::string::npos) << report;
  EXPECT_NE(report.find("list builds in 20 steps"), std::string::npos) << report;
  EXPECT_NE(report.find("candidates"), std::string::npos) << report;
}

}  // namespace
}  // namespace ts::sim
