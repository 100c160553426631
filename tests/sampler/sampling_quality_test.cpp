#include "sampler/sampling_quality.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <random>

#include "tests/test_meshes.h"

namespace ts::sampler {
namespace {

// Rectangle [x0, x1] x [y0, y1] in the plane z = 0, two triangles.
TriangleMesh rectangle(double x0, double y0, double x1, double y1) {
  TriangleMesh mesh;
  mesh.vertices = {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

// Hexagonal lattice of spacing s: rows h = s sqrt(3)/2 apart, odd rows shifted by s/2, nx x ny points
// from the origin. With ny even, the points tile [0, nx s) x [0, ny h) exactly: one point per s h.
std::vector<Eigen::Vector3d> hex_lattice(double s, int nx, int ny) {
  const double h = s * std::sqrt(3.0) / 2.0;
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) points.emplace_back(s * (i + 0.5 * (j % 2)), h * j, 0.0);
  }
  return points;
}

TEST(SamplingQuality, HexSpacingAndParticleCountRule) {
  // One point per hexagon of area sqrt(3)/2 s^2.
  const double s = 0.1;
  EXPECT_NEAR(hex_spacing(1000 * std::sqrt(3.0) / 2.0 * s * s, 1000), s, 1e-15);
  // Covering radius s/sqrt(3) of a hexagonal lattice needs exactly its point count...
  EXPECT_NEAR(particles_for_covering_radius(2.0, s / std::sqrt(3.0)), 2.0 / (std::sqrt(3.0) / 2.0 * s * s), 1e-9);
  // ...and covering with spheres of radius r needs spacing sqrt(3) r: N = 2A / (3 sqrt(3) r^2).
  const double r = 0.01;
  EXPECT_NEAR(particles_for_covering_radius(1.0, r), 2.0 / (3.0 * std::sqrt(3.0) * r * r), 1e-6);
  // A sampler whose holes are deeper for its spacing (k = 0.7) needs more particles.
  EXPECT_GT(particles_for_covering_radius(1.0, r, 0.7), particles_for_covering_radius(1.0, r));
}

TEST(SamplingQuality, HexLatticeHasRelativeRadiusOneAndNoVariation) {
  const double s = 0.05;
  const int nx = 30, ny = 34;
  const std::vector<Eigen::Vector3d> points = hex_lattice(s, nx, ny);
  const double area = nx * s * ny * s * std::sqrt(3.0) / 2.0;
  const SpacingStatistics stats = spacing_statistics(area, points);
  EXPECT_NEAR(stats.d_hex, s, 1e-12);
  EXPECT_NEAR(stats.relative_radius, 1.0, 1e-9);
  EXPECT_NEAR(stats.mean_nn, s, 1e-12);
  EXPECT_LT(stats.cv_nn, 1e-9);
}

TEST(SamplingQuality, HexLatticeCoveringRadiusIsSpacingOverSqrt3) {
  const double s = 0.05;
  const std::vector<Eigen::Vector3d> points = hex_lattice(s, 24, 26);
  // A patch well inside the lattice, so no edge of the point set leaves a hole in it.
  const TriangleMesh patch = rectangle(2 * s, 2 * s, 20 * s, 18 * s);
  CoverageSettings settings;
  settings.probes = 200000;
  const CoverageResult c = measure_coverage(patch, points, settings);
  const double exact = s / std::sqrt(3.0);
  // The probes can only find the deepest point approximately, never beyond it.
  EXPECT_LE(c.covering_radius, exact * (1 + 1e-12));
  EXPECT_GT(c.covering_radius, 0.97 * exact);
  EXPECT_EQ(c.probes, 200000u);
  EXPECT_NEAR(c.deepest.position.z(), 0.0, 1e-15);

  const SamplingQuality q = measure_quality(patch, points, 2.0 * exact, settings);
  EXPECT_DOUBLE_EQ(q.covering_radius, c.covering_radius);
  EXPECT_NEAR(q.covering_over_r, c.covering_radius / (2.0 * exact), 1e-15);
  EXPECT_EQ(q.count, points.size());
  EXPECT_NEAR(q.area, 18 * s * 16 * s, 1e-12);
  // Every sample lies in the plane of the patch, so its distance to the patch is the in-plane
  // distance to the rectangle: zero inside it, the clamped offset outside.
  double farthest = 0.0;
  for (const auto& p : points) {
    const Eigen::Vector3d clamped(std::clamp(p.x(), 2 * s, 20 * s), std::clamp(p.y(), 2 * s, 18 * s), 0.0);
    farthest = std::max(farthest, (p - clamped).norm());
  }
  EXPECT_NEAR(q.max_abs_phi, farthest, 1e-12);
  EXPECT_EQ(q.worst_uncovered_point, c.deepest.position);
}

TEST(SamplingQuality, RandomPointsHaveSmallRelativeRadiusAndPoissonSpread) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 5000; ++i) points.emplace_back(u(rng), u(rng), 0.0);
  const SpacingStatistics stats = spacing_statistics(1.0, points);
  // Formulas.md: random sets reach rho ~ 0.01. Nearest distances of a Poisson process follow a
  // Rayleigh law: mean 0.5 / sqrt(density) = 0.465 d_hex, CV sqrt(4/pi - 1) = 0.523.
  EXPECT_LT(stats.relative_radius, 0.1);
  EXPECT_NEAR(stats.mean_nn / stats.d_hex, 0.465, 0.025);
  EXPECT_NEAR(stats.cv_nn, 0.523, 0.04);
}

TEST(SamplingQuality, CubeCornersLeaveTheSixFaceCentresUncovered) {
  const TriangleMesh cube = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i) corners.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  CoverageSettings settings;
  settings.probes = 300000;
  settings.worst_k = 10;
  settings.separation = 0.5;  // adjacent face centres are 1/sqrt(2) apart, as deep as they are
  const CoverageResult c = measure_coverage(cube, corners, settings);
  EXPECT_LE(c.covering_radius, std::sqrt(0.5) + 1e-12);
  EXPECT_GT(c.covering_radius, 0.98 * std::sqrt(0.5));
  ASSERT_GE(c.worst.size(), 6u);
  std::vector<int> faces_hit(6, 0);
  for (std::size_t k = 0; k < 6; ++k) {
    const UncoveredPoint& p = c.worst[k];
    double nearest_corner = 1e9;
    for (const auto& corner : corners) nearest_corner = std::min(nearest_corner, (corner - p.position).norm());
    EXPECT_DOUBLE_EQ(p.depth, nearest_corner);
    for (int f = 0; f < 6; ++f) {
      Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.5);
      centre[f / 2] = f % 2;
      Eigen::Vector3d outward = Eigen::Vector3d::Zero();
      outward[f / 2] = f % 2 ? 1.0 : -1.0;
      if ((p.position - centre).norm() < 0.1) {
        ++faces_hit[f];
        EXPECT_TRUE(p.normal.isApprox(outward, 1e-12));
      }
    }
    if (k > 0) {
      EXPECT_LE(p.depth, c.worst[k - 1].depth);
    }
  }
  EXPECT_EQ(faces_hit, std::vector<int>(6, 1)) << "one returned point per face centre";
  // The deepest point of all is the first returned.
  EXPECT_DOUBLE_EQ(c.worst[0].depth, c.covering_radius);
}

TEST(SamplingQuality, WorstPointsFindTwoSeparateHoles) {
  const double s = 0.05;
  std::vector<Eigen::Vector3d> points = hex_lattice(s, 24, 26);
  const Eigen::Vector3d hole_a = points[6 * 24 + 5], hole_b = points[19 * 24 + 17];
  std::erase_if(points, [&](const Eigen::Vector3d& p) { return p == hole_a || p == hole_b; });
  const TriangleMesh patch = rectangle(2 * s, 2 * s, 20 * s, 18 * s);
  CoverageSettings settings;
  settings.probes = 200000;
  settings.worst_k = 2;
  const CoverageResult c = measure_coverage(patch, points, settings);
  // A missing lattice point leaves a hole as deep as the spacing (its six neighbours).
  EXPECT_LE(c.covering_radius, s * (1 + 1e-12));
  EXPECT_GT(c.covering_radius, 0.95 * s);
  ASSERT_EQ(c.worst.size(), 2u);
  const double da = std::min((c.worst[0].position - hole_a).norm(), (c.worst[1].position - hole_a).norm());
  const double db = std::min((c.worst[0].position - hole_b).norm(), (c.worst[1].position - hole_b).norm());
  EXPECT_LT(da, 0.1 * s);
  EXPECT_LT(db, 0.1 * s);
  // Only holes deeper than min_depth are returned: the lattice's own holes are s/sqrt(3) deep.
  settings.worst_k = 50;
  settings.min_depth = 0.8 * s;
  EXPECT_EQ(measure_coverage(patch, points, settings).worst.size(), 2u);
}

TEST(SamplingQuality, CoverageIsDeterministicForASeedWhateverTheThreadCount) {
  const TriangleMesh sphere = test::icosphere(1.0, 3);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3f> samples;
  while (samples.size() < 500) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    if (p.norm() > 0.1) samples.push_back(p.normalized().cast<float>());
  }
  CoverageSettings settings;
  settings.probes = 100000;
  settings.worst_k = 5;
  settings.seed = 77;
  const CoverageResult parallel = measure_coverage(sphere, samples, settings);
  CoverageResult serial;
  {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    serial = measure_coverage(sphere, samples, settings);
  }
  EXPECT_EQ(parallel.covering_radius, serial.covering_radius);
  ASSERT_EQ(parallel.worst.size(), serial.worst.size());
  for (std::size_t k = 0; k < parallel.worst.size(); ++k) {
    EXPECT_EQ(parallel.worst[k].position, serial.worst[k].position);
    EXPECT_EQ(parallel.worst[k].depth, serial.worst[k].depth);
  }
  settings.seed = 78;
  EXPECT_NE(measure_coverage(sphere, samples, settings).deepest.position, parallel.deepest.position);
}

TEST(SamplingQuality, MaxDistanceToSurfaceIsTheExactDistance) {
  const TriangleMesh cube = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const std::vector<Eigen::Vector3d> on_surface = {{0.5, 0.5, 1.0}, {0.0, 0.3, 0.7}, {1.0, 1.0, 1.0}};
  EXPECT_LT(max_distance_to_surface(cube, on_surface), 1e-12);
  std::vector<Eigen::Vector3d> off = on_surface;
  off.emplace_back(0.5, 0.5, 1.2);   // 0.2 above the top face
  off.emplace_back(0.5, 0.45, 0.5);  // inside: 0.45 from the face y = 0
  EXPECT_NEAR(max_distance_to_surface(cube, off), 0.45, 1e-12);
  off.emplace_back(2.0, 2.0, 2.0);   // beyond a corner
  EXPECT_NEAR(max_distance_to_surface(cube, off), std::sqrt(3.0), 1e-12);
}

}  // namespace
}  // namespace ts::sampler
