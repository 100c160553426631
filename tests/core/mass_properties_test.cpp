#include "core/mass_properties.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/mesh_report.h"
#include "core/primitives.h"

namespace ts {
namespace {

TEST(MassProperties, CubeMatchesAnalytic) {
  const double a = 0.2, density = 2500.0;
  const MassProperties m = compute_mass_properties(make_box({0, 0, 0}, {a, a, a}), density);
  EXPECT_NEAR(m.volume, a * a * a, 1e-15);
  EXPECT_NEAR(m.mass, density * a * a * a, 1e-12);
  EXPECT_LT((m.center_of_mass - Eigen::Vector3d::Constant(a / 2)).norm(), 1e-15);
  const double expected = m.mass * a * a / 6.0;
  EXPECT_LT((m.inertia - expected * Eigen::Matrix3d::Identity()).norm(), 1e-12 * expected);
}

TEST(MassProperties, SphereMatchesAnalyticUpToTessellation) {
  // The polyhedron is inscribed: compare with the analytic sphere within the volume deficit of the
  // tessellation (computed from the polyhedron itself), which shrinks with subdivision.
  const double r = 0.1;
  double previous_error = 1e300;
  for (int s : {3, 4, 5}) {
    const MassProperties m = compute_mass_properties(make_icosphere(r, s), 1000.0);
    const double sphere_volume = 4.0 / 3.0 * M_PI * r * r * r;
    const double deficit = 1.0 - m.volume / sphere_volume;
    EXPECT_GT(deficit, 0.0);
    const double expected = 0.4 * m.mass * r * r;
    const double error = std::abs(m.principal_moments.x() / expected - 1.0);
    // Mass at radius r is what goes missing: the inertia deficit is within ~(5/3) of the volume's.
    EXPECT_LT(error, 2.0 * deficit) << s;
    EXPECT_LT(error, previous_error);
    previous_error = error;
    EXPECT_LT(m.center_of_mass.norm(), 1e-15);
  }
}

TEST(MassProperties, TetrahedronMatchesAnalytic) {
  // Unit right tetrahedron: V = 1/6, centroid (1/4, 1/4, 1/4); about the origin, with rho = 1,
  // Ixx = 1/30 and products of inertia Ixy = -1/120 (Tonon 2004).
  TriangleMesh tet;
  tet.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const MassProperties m = compute_mass_properties(tet, 1.0);
  EXPECT_NEAR(m.volume, 1.0 / 6.0, 1e-15);
  EXPECT_LT((m.center_of_mass - Eigen::Vector3d::Constant(0.25)).norm(), 1e-15);
  const Eigen::Vector3d c = m.center_of_mass;
  // Parallel-axis theorem back to the origin.
  const Eigen::Matrix3d about_origin = m.inertia + m.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  EXPECT_NEAR(about_origin(0, 0), 1.0 / 30.0, 1e-15);
  EXPECT_NEAR(about_origin(0, 1), -1.0 / 120.0, 1e-15);
}

TEST(MassProperties, RotatedAndTranslatedCopiesTransformCovariantly) {
  const TriangleMesh base = make_torus(0.3, 0.1, 48, 16);
  const MassProperties m0 = compute_mass_properties(base, 7800.0);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (const Eigen::Vector3d& t : {Eigen::Vector3d(1, -2, 3), Eigen::Vector3d(1e4, -2e4, 5e3)}) {
    TriangleMesh moved = base;
    for (auto& v : moved.vertices) v = r * v + t;
    const MassProperties m = compute_mass_properties(moved, 7800.0);
    EXPECT_NEAR(m.mass / m0.mass, 1.0, 1e-9);
    EXPECT_LT((m.center_of_mass - (r * m0.center_of_mass + t)).norm(), 1e-9 * (1.0 + t.norm()));
    EXPECT_LT((m.inertia - r * m0.inertia * r.transpose()).norm(), 1e-9 * m0.inertia.norm()) << t.transpose();
    EXPECT_LT((m.principal_moments - m0.principal_moments).norm(), 1e-9 * m0.principal_moments.norm());
    EXPECT_GT(m.principal_axes.determinant(), 0.0);
  }
}

TEST(MassProperties, PrincipalAxesAreSortedAscendingAndRightHanded) {
  // Box 1 x 2 x 3 m: I = m/12 (b^2 + c^2, ...) = m/12 (13, 10, 5): ascending means z, y, x.
  const Eigen::Matrix3d r = Eigen::AngleAxisd(-1.1, Eigen::Vector3d(3, -1, 2).normalized()).toRotationMatrix();
  TriangleMesh box = make_box(Eigen::Vector3d(1, 2, 3));
  for (auto& v : box.vertices) v = r * v;
  const MassProperties m = compute_mass_properties(box, 1000.0);
  EXPECT_NEAR(m.mass, 6000.0, 1e-9);
  const Eigen::Vector3d expected = m.mass / 12.0 * Eigen::Vector3d(5, 10, 13);
  EXPECT_LT((m.principal_moments - expected).norm(), 1e-9 * expected.norm());
  EXPECT_NEAR(std::abs(m.principal_axes.col(0).dot(r.col(2))), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(m.principal_axes.col(1).dot(r.col(1))), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(m.principal_axes.col(2).dot(r.col(0))), 1.0, 1e-12);
  EXPECT_NEAR(m.principal_axes.determinant(), 1.0, 1e-12);
  // The axes diagonalise the inertia tensor.
  const Eigen::Matrix3d diagonal = m.principal_axes.transpose() * m.inertia * m.principal_axes;
  EXPECT_LT((diagonal - Eigen::Matrix3d(expected.asDiagonal())).norm(), 1e-9 * expected.norm());
}

std::string mass_error(const TriangleMesh& mesh, double density = 1000.0) {
  try {
    compute_mass_properties(mesh, density);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MassProperties, InsideOutOrOpenMeshIsRejected) {
  TriangleMesh inside_out = make_box({0, 0, 0}, {1, 1, 1});
  for (auto& t : inside_out.triangles) std::swap(t[1], t[2]);
  EXPECT_NE(mass_error(inside_out).find("inside out"), std::string::npos) << mass_error(inside_out);
  // Without its -x face the divergence sum is still positive (0.5 m^3): only the edge check sees it.
  TriangleMesh open = make_box({0, 0, 0}, {1, 1, 1});
  open.triangles.erase(open.triangles.begin() + 8, open.triangles.begin() + 10);
  EXPECT_NE(mass_error(open).find("closed"), std::string::npos) << mass_error(open);
  TriangleMesh flipped = make_box({0, 0, 0}, {1, 1, 1});
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_NE(mass_error(flipped).find("flipped"), std::string::npos) << mass_error(flipped);
  EXPECT_NE(mass_error(make_box({0, 0, 0}, {1, 1, 1}), -5.0).find("density"), std::string::npos);
}

TEST(MassProperties, ReportPredictsWhetherMassPropertiesAreAccepted) {
  std::vector<TriangleMesh> meshes(5, make_box({0, 0, 0}, {1, 1, 1}));
  for (auto& t : meshes[1].triangles) std::swap(t[1], t[2]);  // inside out
  meshes[2].triangles.pop_back();                              // open
  std::swap(meshes[3].triangles[0][1], meshes[3].triangles[0][2]);  // one flipped face
  for (auto& v : meshes[4].vertices) v.z() = 0.0;              // flat: closed but no volume
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const bool accepted = mass_error(meshes[i]).empty();
    EXPECT_EQ(encloses_volume(analyze_mesh(meshes[i])), accepted) << i << ": " << mass_error(meshes[i]);
    EXPECT_EQ(accepted, i == 0) << i;
  }
}

TEST(MassProperties, TwoBoxesSharingAnEdgeAddUp) {
  // A non-manifold edge still bounds a region: the divergence theorem holds, so this is accepted.
  TriangleMesh two = make_box({0, 0, 0}, {1, 1, 1});
  const TriangleMesh other = make_box({1, 1, 0}, {2, 2, 1});
  // Weld the two shared corners so that the edge between them belongs to four triangles.
  std::vector<std::uint32_t> index(other.vertices.size());
  for (std::size_t i = 0; i < other.vertices.size(); ++i) {
    const auto same = std::find(two.vertices.begin(), two.vertices.end(), other.vertices[i]);
    index[i] = static_cast<std::uint32_t>(same - two.vertices.begin());
    if (same == two.vertices.end()) two.vertices.push_back(other.vertices[i]);
  }
  for (const auto& t : other.triangles) two.triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
  ASSERT_EQ(two.vertices.size(), 14u);
  const MassProperties m = compute_mass_properties(two, 1.0);
  EXPECT_NEAR(m.volume, 2.0, 1e-12);
  EXPECT_LT((m.center_of_mass - Eigen::Vector3d(1, 1, 0.5)).norm(), 1e-12);
}

}  // namespace
}  // namespace ts
