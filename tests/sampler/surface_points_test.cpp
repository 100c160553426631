#include "sampler/surface_points.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numeric>

#include "core/error.h"
#include "tests/test_meshes.h"

namespace ts::sampler {
namespace {

// Separate triangles in the plane z = 0; triangle k has area (k + 1) / 2 m^2.
TriangleMesh triangles_of_growing_area(int n) {
  TriangleMesh mesh;
  for (int k = 0; k < n; ++k) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    const double y = 2.0 * k;
    mesh.vertices.emplace_back(0.0, y, 0.0);
    mesh.vertices.emplace_back(k + 1.0, y, 0.0);
    mesh.vertices.emplace_back(0.0, y + 1.0, 0.0);
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

// Pearson's statistic of observed counts against expected probabilities.
double chi_square(const std::vector<std::size_t>& observed, const std::vector<double>& probability) {
  const double total = static_cast<double>(std::accumulate(observed.begin(), observed.end(), std::size_t{0}));
  double chi2 = 0.0;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    const double expected = total * probability[i];
    chi2 += (static_cast<double>(observed[i]) - expected) * (static_cast<double>(observed[i]) - expected) / expected;
  }
  return chi2;
}

TEST(SurfacePoints, SameSeedGivesTheSamePointsAndAnotherSeedOthers) {
  const TriangleMesh mesh = test::icosphere(1.0, 2);
  std::mt19937_64 a(42), b(42), c(43);
  const SurfacePoints pa = sample_surface_points(mesh, 500, a);
  const SurfacePoints pb = sample_surface_points(mesh, 500, b);
  const SurfacePoints pc = sample_surface_points(mesh, 500, c);
  ASSERT_EQ(pa.positions.size(), 500u);
  EXPECT_EQ(pa.positions, pb.positions);
  EXPECT_EQ(pa.triangles, pb.triangles);
  EXPECT_NE(pa.positions, pc.positions);
}

TEST(SurfacePoints, PointsLieInsideTheTriangleTheyReport) {
  const TriangleMesh mesh = test::icosphere(2.0, 1);
  std::mt19937_64 rng(7);
  const SurfacePoints s = sample_surface_points(mesh, 2000, rng);
  for (std::size_t i = 0; i < s.positions.size(); ++i) {
    const auto& t = mesh.triangles[s.triangles[i]];
    const Eigen::Vector3d a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const Eigen::Vector3d p = s.positions[i];
    // Barycentric coordinates from signed sub-areas: all in [0, 1] inside, and p in the plane.
    const double u = (c - b).cross(p - b).dot(n) / n.squaredNorm();
    const double v = (a - c).cross(p - c).dot(n) / n.squaredNorm();
    const double w = (b - a).cross(p - a).dot(n) / n.squaredNorm();
    EXPECT_NEAR(u + v + w, 1.0, 1e-12);
    EXPECT_GE(std::min({u, v, w}), -1e-12);
    EXPECT_NEAR((p - a).dot(n.normalized()), 0.0, 1e-12);
    EXPECT_NEAR(s.normals[i].norm(), 1.0, 1e-12);
    EXPECT_GT(s.normals[i].dot(p), 0.0) << "icosphere normals point outward";
  }
}

TEST(SurfacePoints, TriangleCountsFollowAreas) {
  const int n = 8;
  const TriangleMesh mesh = triangles_of_growing_area(n);
  std::mt19937_64 rng(2024);
  const SurfacePoints s = sample_surface_points(mesh, 200000, rng);
  std::vector<std::size_t> counts(n, 0);
  for (const std::uint32_t t : s.triangles) ++counts[t];
  std::vector<double> probability(n);
  for (int k = 0; k < n; ++k) probability[k] = (k + 1.0) / (n * (n + 1) / 2.0);
  // 7 degrees of freedom: P(chi2 > 24.32) = 0.001.
  EXPECT_LT(chi_square(counts, probability), 24.32);
  // A generator that ignored areas would be far off: the statistic has the power to see it.
  EXPECT_GT(chi_square(counts, std::vector<double>(n, 1.0 / n)), 1000.0);
}

TEST(SurfacePoints, UniformInsideATriangle) {
  // The midpoint subdivision of one triangle into four equal triangles: each gets a quarter.
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {3, 0, 0}, {1, 2, 0}};
  mesh.triangles = {{0, 1, 2}};
  std::mt19937_64 rng(99);
  const SurfacePoints s = sample_surface_points(mesh, 100000, rng);
  std::vector<std::size_t> counts(4, 0);
  const Eigen::Vector3d a = mesh.vertices[0], b = mesh.vertices[1], c = mesh.vertices[2];
  for (const Eigen::Vector3d& p : s.positions) {
    // Barycentric coordinate of each corner: > 1/2 means the corner's sub-triangle.
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double u = (c - b).cross(p - b).dot(n) / n.squaredNorm();
    const double v = (a - c).cross(p - c).dot(n) / n.squaredNorm();
    const double w = 1.0 - u - v;
    ++counts[u > 0.5 ? 0 : v > 0.5 ? 1 : w > 0.5 ? 2 : 3];
  }
  // 3 degrees of freedom: P(chi2 > 16.27) = 0.001.
  EXPECT_LT(chi_square(counts, {0.25, 0.25, 0.25, 0.25}), 16.27);
}

TEST(SurfacePoints, ZeroAreaTrianglesAreNeverPicked) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  // A degenerate triangle first, between and last (the last is where rounding of u up to 1 lands).
  mesh.triangles = {{0, 1, 3}, {0, 1, 2}, {0, 0, 0}, {1, 2, 0}, {3, 1, 0}};
  std::mt19937_64 rng(5);
  const SurfacePoints s = sample_surface_points(mesh, 20000, rng);
  for (const std::uint32_t t : s.triangles) EXPECT_TRUE(t == 1 || t == 3) << t;
  const AreaTable table(mesh);
  EXPECT_EQ(table.pick_triangle(0.0), 1u);
  EXPECT_EQ(table.pick_triangle(std::nextafter(1.0, 0.0)), 3u);
  EXPECT_DOUBLE_EQ(table.total_area(), 1.0);
}

TEST(SurfacePoints, MeshWithoutAreaIsAnInputError) {
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}};
  std::mt19937_64 rng(1);
  EXPECT_THROW(sample_surface_points(flat, 10, rng), InputError);
  EXPECT_THROW(sample_surface_points(TriangleMesh{}, 10, rng), InputError);
}

}  // namespace
}  // namespace ts::sampler
