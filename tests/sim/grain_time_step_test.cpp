#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/grain.h"
#include "sim/time_step.h"

namespace ts::sim {
namespace {

TEST(TetrahedralGrain, TouchingSpheresFormARegularTetrahedron) {
  const GrainShape g = make_tetrahedral_grain(1e-3, 2e-3, 2600);
  EXPECT_NEAR(g.centre_distance, 2e-3 * std::sqrt(3.0 / 8.0), 1e-15);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < 4; ++i) {
    centroid += g.offsets[i];
    EXPECT_NEAR(g.offsets[i].norm(), g.centre_distance, 1e-15);
    for (int j = i + 1; j < 4; ++j) EXPECT_NEAR((g.offsets[i] - g.offsets[j]).norm(), 2e-3, 1e-15);
  }
  EXPECT_LT(centroid.norm(), 1e-15);
  EXPECT_NEAR(g.bounding_radius, 1.1124 * 2e-3, 1e-6);  // 1.11 d (notes/peers.md)
}

TEST(TetrahedralGrain, InertiaMatchesSumOverSpheres) {
  const double r = 1e-3, density = 2600;
  const GrainShape g = make_tetrahedral_grain(r, 1.6e-3, density);
  EXPECT_NEAR(g.mass, density * 4 * 4.0 / 3.0 * std::numbers::pi * r * r * r, 1e-18);
  // Parallel-axis sum over the four spheres, computed directly.
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  const double m = g.mass / 4;
  for (const auto& o : g.offsets) {
    inertia += m * (o.squaredNorm() * Eigen::Matrix3d::Identity() - o * o.transpose()) +
               0.4 * m * r * r * Eigen::Matrix3d::Identity();
  }
  EXPECT_LT((inertia - g.inertia * Eigen::Matrix3d::Identity()).norm(), 1e-9 * g.inertia);
}

TEST(TimeStep, HertzDurationFollowsTheSpeedPowerLaw) {
  const double t1 = hertz_contact_duration(1e-5, 5e-4, 5e6, 1.0);
  const double t32 = hertz_contact_duration(1e-5, 5e-4, 5e6, 32.0);
  EXPECT_NEAR(t1 / t32, 2.0, 1e-12);  // v^(-1/5)
  // Second form of eq. 3.22: 2.87 (m*^2 / (R* E*^2 v))^(1/5).
  EXPECT_NEAR(t1, 2.87 * std::pow(1e-10 / (5e-4 * 25e12), 0.2), 0.01 * t1);
}

TEST(TimeStep, RecommendedStepIsTheSmallerBound) {
  Material m;
  const TimeStepBound b = time_step_bound({{1e-5, 5e-4, 5e6}}, {{1e-3, m}}, 5.0);
  EXPECT_DOUBLE_EQ(b.recommended, std::min(b.contact_duration / 20, 0.2 * b.rayleigh));
  EXPECT_GT(b.rayleigh, 0);
  EXPECT_EQ(check_time_step(b.recommended, b), "");
}

TEST(TimeStep, StepAboveTheBoundWarnsWithTheBound) {
  Material m;
  const TimeStepBound b = time_step_bound({{1e-5, 5e-4, 5e6}}, {{1e-3, m}}, 5.0);
  const std::string warning = check_time_step(10 * b.recommended, b);
  ASSERT_NE(warning, "");
  EXPECT_NE(warning.find(fmt::format("{:.3g}", b.recommended)), std::string::npos) << warning;
}

}  // namespace
}  // namespace ts::sim
