// Angle-weighted pseudonormals: unit length, the known normals of a cube's features, and no NaN from
// degenerate triangles.
#include "sdf/pseudonormals.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_meshes.h"

namespace ts::sdf {
namespace {

// The vertex of `mesh` nearest to p.
std::uint32_t vertex_at(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  std::uint32_t best = 0;
  for (std::uint32_t v = 1; v < mesh.vertex_count(); ++v)
    if ((mesh.vertices[v] - p).norm() < (mesh.vertices[best] - p).norm()) best = v;
  return best;
}

TEST(Pseudonormals, CubeCornerEdgeAndFaceNormalsAreTheSymmetricOnes) {
  const TriangleMesh cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const Pseudonormals n = compute_pseudonormals(cube);
  EXPECT_EQ(n.degenerate_triangles, 0u);
  const std::uint32_t corner = vertex_at(cube, {1, 1, 1});
  const std::uint32_t below = vertex_at(cube, {1, 1, 0});
  int corners_seen = 0, edges_seen = 0;
  for (std::size_t t = 0; t < cube.triangle_count(); ++t) {
    const auto& tri = cube.triangles[t];
    // Each face normal is an axis: exactly one coordinate of magnitude one.
    EXPECT_NEAR(n.face[t].cwiseAbs().maxCoeff(), 1.0, 1e-15);
    EXPECT_NEAR(n.face[t].cwiseAbs().sum(), 1.0, 1e-15);
    for (std::size_t k = 0; k < 3; ++k) {
      // Every corner of the cube is a corner of some triangles: whatever their number (3 to 6, by the
      // triangulation), the angle weights make the pseudonormal symmetric.
      if (tri[k] == corner) {
        EXPECT_LT((n.vertex[t][k] - Eigen::Vector3d::Constant(1.0 / std::sqrt(3.0))).norm(), 1e-12);
        ++corners_seen;
      }
      const std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
      if ((a == corner && b == below) || (a == below && b == corner)) {
        EXPECT_LT((n.edge[t][k] - Eigen::Vector3d(1, 1, 0) / std::sqrt(2.0)).norm(), 1e-12);
        ++edges_seen;
      }
    }
  }
  EXPECT_GE(corners_seen, 3);
  EXPECT_EQ(edges_seen, 2);  // a manifold edge: in two triangles
}

TEST(Pseudonormals, SphereNormalsAreUnitAndPointOutward) {
  const TriangleMesh sphere = test::icosphere(1.0, 2);
  const Pseudonormals n = compute_pseudonormals(sphere);
  ASSERT_EQ(n.face.size(), sphere.triangle_count());
  for (std::size_t t = 0; t < sphere.triangle_count(); ++t) {
    EXPECT_NEAR(n.face[t].norm(), 1.0, 1e-14);
    for (std::size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d& v = sphere.vertices[sphere.triangles[t][k]];
      EXPECT_NEAR(n.vertex[t][k].norm(), 1.0, 1e-14);
      EXPECT_NEAR(n.edge[t][k].norm(), 1.0, 1e-14);
      // On an icosphere the vertex pseudonormal is close to the radial direction.
      EXPECT_GT(n.vertex[t][k].dot(v.normalized()), 0.99);
      const Eigen::Vector3d mid = 0.5 * (v + sphere.vertices[sphere.triangles[t][(k + 1) % 3]]);
      EXPECT_GT(n.edge[t][k].dot(mid.normalized()), 0.99);
    }
  }
}

TEST(Pseudonormals, BoundaryEdgeTakesItsFaceNormal) {
  TriangleMesh single;
  single.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  single.triangles = {{0, 1, 2}};
  const Pseudonormals n = compute_pseudonormals(single);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(n.edge[0][k], Eigen::Vector3d::UnitZ());
    EXPECT_EQ(n.vertex[0][k], Eigen::Vector3d::UnitZ());
  }
}

TEST(Pseudonormals, DegenerateTrianglesAreCountedAndGiveNoNaN) {
  TriangleMesh mesh = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const std::size_t good = mesh.triangle_count();
  const auto v = static_cast<std::uint32_t>(mesh.vertex_count());
  mesh.vertices.push_back({0.2, 0.3, 1.0});
  mesh.vertices.push_back({0.4, 0.3, 1.0});
  mesh.vertices.push_back({0.6, 0.3, 1.0});
  mesh.triangles.push_back({v, v + 1, v + 2});  // collinear
  mesh.triangles.push_back({v, v, v + 1});      // repeated corner
  mesh.triangles.push_back({v, v, v});          // a point
  // A degenerate triangle sharing a cube vertex must not bend that vertex's pseudonormal.
  const std::uint32_t corner = vertex_at(mesh, {1, 1, 1});
  mesh.triangles.push_back({corner, corner, v});
  const Pseudonormals n = compute_pseudonormals(mesh);
  EXPECT_EQ(n.degenerate_triangles, 4u);
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    EXPECT_TRUE(n.face[t].allFinite());
    EXPECT_NEAR(n.face[t].norm(), 1.0, 1e-14);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_TRUE(n.edge[t][k].allFinite()) << t;
      EXPECT_TRUE(n.vertex[t][k].allFinite()) << t;
      EXPECT_NEAR(n.vertex[t][k].norm(), 1.0, 1e-14);
    }
  }
  for (std::size_t t = 0; t < good; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      if (mesh.triangles[t][k] == corner) {
        EXPECT_LT((n.vertex[t][k] - Eigen::Vector3d::Constant(1.0 / std::sqrt(3.0))).norm(), 1e-12);
      }
    }
  }
}

}  // namespace
}  // namespace ts::sdf
