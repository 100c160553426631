#include "sdf/exact_sdf.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <random>

#include "gpu/context.h"
#include "sdf/openvdb_compare.h"
#include "sdf/scan_convert.h"
#include "tests/test_meshes.h"

namespace ts::sdf {
namespace {

TEST(ExactDistance, SphereMatchesAnalyticWithinTheFacetError) {
  const double r = 1.0;
  const TriangleMesh sphere = test::icosphere(r, 3);
  const ExactDistance exact(sphere);
  // Facets of an inscribed icosphere sit at most r (1 - cos(edge angle)) inside the sphere.
  const double facet = 0.01;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const double d = exact.signed_distance(p, SignMethod::Pseudonormal);
    EXPECT_NEAR(d, p.norm() - r, facet) << p.transpose();
    EXPECT_EQ(d < 0, exact.signed_distance(p, SignMethod::Winding) < 0) << p.transpose();
  }
}

TEST(ExactDistance, ClassifiesFaceEdgeAndVertexOfACube) {
  const ExactDistance exact(test::box_mesh({0, 0, 0}, {1, 1, 1}));
  // (0.5, 0.5) would be on the diagonal both top triangles share: an edge, with the face's normal.
  EXPECT_EQ(exact.closest({0.3, 0.6, 2.0}).feature, Feature::Face);
  EXPECT_EQ(exact.closest({0.5, 2.0, 2.0}).feature, Feature::Edge);
  EXPECT_EQ(exact.closest({2.0, 2.0, 2.0}).feature, Feature::Vertex);
  const ClosestPoint corner = exact.closest({2.0, 2.0, 2.0});
  EXPECT_LT((exact.feature_normal(corner) - Eigen::Vector3d::Constant(1.0 / std::sqrt(3.0))).norm(), 1e-12);
  EXPECT_NEAR(exact.signed_distance({0.5, 0.5, 0.5}, SignMethod::Pseudonormal), -0.5, 1e-15);
}

TEST(ExactDistance, WindingNumberKeepsTheInsideOfAnOpenMesh) {
  TriangleMesh open = test::icosphere(1.0, 2);
  open.triangles.resize(open.triangles.size() - 3);  // punch a small hole
  const ExactDistance exact(open);
  EXPECT_GT(exact.winding_number({0, 0, 0}), 0.9);
  EXPECT_LT(exact.winding_number({0, 0, 3}), 0.1);
  EXPECT_LT(exact.signed_distance({0.1, 0.2, 0.0}, SignMethod::Winding), 0.0);
}

TEST(ExactSdf, GpuScanConversionMatchesTheExactGrid) {
  gpu::Context context;
  for (const auto& mesh : {test::box_mesh({-0.5, -0.4, -0.3}, {0.5, 0.4, 0.3}), test::icosphere(0.5, 2)}) {
    SdfSettings settings;
    settings.resolution = 24;
    const GridSpec spec = make_grid(bounding_box(mesh), settings);
    const auto exact = exact_sdf_grid(mesh, spec, 3.0, SignMethod::Pseudonormal);
    ScanConvertOptions options;
    const auto gpu = scan_convert(context, mesh, compute_pseudonormals(mesh), spec, options);
    const GridComparison c = compare_grids(*gpu.grid, *exact, spec.voxel_size, 3.0 * spec.voxel_size);
    EXPECT_GT(c.voxels, 1000u);
    EXPECT_LE(c.max, 1e-3);
    EXPECT_EQ(c.sign_disagreements, 0u);
  }
}

// The unit box with three degenerate triangles on its top face: collinear, a repeated corner, a point.
TriangleMesh box_with_degenerate_triangles() {
  TriangleMesh mesh = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const auto v = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.push_back({0.2, 0.3, 1.0});
  mesh.vertices.push_back({0.4, 0.3, 1.0});
  mesh.vertices.push_back({0.6, 0.3, 1.0});
  mesh.triangles.push_back({v, v + 1, v + 2});  // collinear: zero area
  mesh.triangles.push_back({v, v, v + 1});      // a repeated corner
  mesh.triangles.push_back({v, v, v});          // a point
  return mesh;
}

TEST(ExactDistance, DegenerateTrianglesGiveFiniteDistancesAndSigns) {
  TriangleMesh mesh = box_with_degenerate_triangles();
  const ExactDistance exact(mesh);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    for (SignMethod sign : {SignMethod::Pseudonormal, SignMethod::Winding}) {
      const double d = exact.signed_distance(p, sign);
      ASSERT_TRUE(std::isfinite(d)) << p.transpose();
      const bool inside = (p.array() > 0.0).all() && (p.array() < 1.0).all();
      const double box_distance = inside ? -(p.array().min(1.0 - p.array())).minCoeff()
                                         : (p - p.cwiseMax(Eigen::Vector3d::Zero()).cwiseMin(Eigen::Vector3d::Ones())).norm();
      EXPECT_NEAR(d, box_distance, 1e-12) << p.transpose();
    }
  }
  const ClosestPoint on_needle = exact.closest({0.3, 0.3, 1.5});
  EXPECT_NEAR(on_needle.distance, 0.5, 1e-12);
  EXPECT_TRUE(on_needle.point.allFinite());
}

TEST(ExactSdf, DenseFieldIsTheBandClampedWithFloodFilledSigns) {
  const TriangleMesh sphere = test::icosphere(0.5, 2);
  SdfSettings settings;
  settings.resolution = 16;
  settings.padding = 6;
  const GridSpec spec = make_grid(bounding_box(sphere), settings);
  const double band = 2.0 * spec.voxel_size;
  const std::vector<float> dense = exact_sdf_dense(sphere, spec, 2.0, SignMethod::Pseudonormal);
  ASSERT_EQ(dense.size(), spec.voxel_count());
  const ExactDistance exact(sphere);
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const double d = exact.signed_distance(spec.voxel_center(i, j, k), SignMethod::Pseudonormal);
        const double expected = std::clamp(d, -band, band);
        ASSERT_NEAR(dense[spec.linear_index(i, j, k)], expected, 1e-6 * spec.voxel_size) << i << " " << j << " " << k;
      }
}

// The grid is built by a sweep over the triangles (each visits the voxels within the band of its
// plane); single points by the AABB tree. Large slanted faces (whose boxes hold far more voxels than
// their band), faces parallel and perpendicular to x, and degenerate triangles must all give the
// tree's distance and sign at every voxel.
TEST(ExactSdf, TriangleSweepGivesTheTreesDistanceAtEveryVoxel) {
  const TriangleMesh base = box_with_degenerate_triangles();
  const Eigen::Quaterniond turns[] = {Eigen::Quaterniond::Identity(),
                                      Eigen::Quaterniond(0.9, 0.3, -0.2, 0.25).normalized()};
  for (const Eigen::Quaterniond& turn : turns) {
    TriangleMesh mesh = base;
    for (Eigen::Vector3d& x : mesh.vertices) x = turn * x;
    SdfSettings settings;
    settings.resolution = 40;
    settings.padding = 5;
    const GridSpec spec = make_grid(bounding_box(mesh), settings);
    const double band_voxels = 3.0, band = band_voxels * spec.voxel_size;
    const std::vector<float> dense = exact_sdf_dense(mesh, spec, band_voxels, SignMethod::Pseudonormal);
    const ExactDistance exact(mesh);
    std::size_t in_band = 0;
    for (int k = 0; k < spec.dims.z(); ++k)
      for (int j = 0; j < spec.dims.y(); ++j)
        for (int i = 0; i < spec.dims.x(); ++i) {
          const double d = exact.signed_distance(spec.voxel_center(i, j, k), SignMethod::Pseudonormal);
          in_band += std::abs(d) < band;
          ASSERT_NEAR(dense[spec.linear_index(i, j, k)], std::clamp(d, -band, band), 1e-6 * spec.voxel_size)
              << i << " " << j << " " << k << " turned " << turn.coeffs().transpose();
        }
    EXPECT_GT(in_band, 1000u);
  }
}

TEST(ExactDistance, ClosestOnAGivenTriangleIsTheTreesAnswerOnTheTreesTriangle) {
  const TriangleMesh mesh = test::icosphere(0.5, 2);
  const ExactDistance exact(mesh);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.8, 0.8);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const ClosestPoint tree = exact.closest(p);
    const ClosestPoint given = exact.closest_on(p, tree.triangle);
    EXPECT_NEAR(given.distance, tree.distance, 1e-12) << p.transpose();
    EXPECT_LT((given.point - tree.point).norm(), 1e-12) << p.transpose();
    EXPECT_EQ(given.feature, tree.feature) << p.transpose();
  }
}

}  // namespace
}  // namespace ts::sdf
