// Generalised winding number: the solid-angle formula, the hierarchical approximation against the
// direct sum, and inside/outside on open meshes (libcgal-demo's elephant with holes).
#include "sdf/winding_number.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <utility>

#include "core/mesh_io.h"
#include "sdf/exact_sdf.h"
#include "tests/test_meshes.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

std::vector<Eigen::Vector3d> random_points(const Aabb& box, int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < count; ++k)
    points.push_back(box.min + Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(box.size()));
  return points;
}

TEST(SolidAngle, OctantTriangleCoversAnEighthOfTheSphere) {
  const Eigen::Vector3d x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  EXPECT_NEAR(solid_angle(x, y, z), 4.0 * std::numbers::pi / 8.0, 1e-14);
  EXPECT_NEAR(solid_angle(x, z, y), -4.0 * std::numbers::pi / 8.0, 1e-14);  // seen from the front
  // Degenerate triangles and a viewpoint on a corner add nothing, and no NaN.
  EXPECT_EQ(solid_angle(x, 2 * x, 3 * x), 0.0);
  EXPECT_EQ(solid_angle(x, x, y), 0.0);
  EXPECT_TRUE(std::isfinite(solid_angle(Eigen::Vector3d::Zero(), y, z)));
}

TEST(WindingNumber, ClosedSphereIsOneInsideAndZeroOutside) {
  const TriangleMesh sphere = test::icosphere(1.0, 3);
  const FastWindingNumber fast(sphere);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3d direction = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double r = k % 2 == 0 ? 0.9 * std::abs(u(rng)) : 1.1 + 3.0 * std::abs(u(rng));
    const Eigen::Vector3d p = r * direction;
    const double expected = r < 1.0 ? 1.0 : 0.0;
    EXPECT_NEAR(winding_number_direct(sphere, p), expected, 1e-9) << p.transpose();
    EXPECT_NEAR(fast(p), expected, 0.05) << p.transpose();
  }
}

TEST(WindingNumber, HierarchyMatchesTheDirectSumNearAndFar) {
  const TriangleMesh torus = make_torus(1.0, 0.3, 48, 24);
  const FastWindingNumber fast(torus), accurate(torus, 6.0);
  EXPECT_GT(fast.node_count(), 100u);
  Aabb box = bounding_box(torus);
  box.extend(box.min - Eigen::Vector3d::Constant(0.5));
  box.extend(box.max + Eigen::Vector3d::Constant(0.5));
  const auto points = random_points(box, 2000, 11);
  const std::vector<double> many = fast.evaluate(points);
  double worst = 0.0, worst_accurate = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double direct = winding_number_direct(torus, points[i]);
    worst = std::max(worst, std::abs(many[i] - direct));
    worst_accurate = std::max(worst_accurate, std::abs(accurate(points[i]) - direct));
    EXPECT_EQ(many[i], fast(points[i]));
  }
  EXPECT_LT(worst, 0.05);
  EXPECT_LT(worst_accurate, 3e-3);
  EXPECT_LT(worst_accurate, worst);
}

TEST(WindingNumber, InwardOrientedMeshIsMinusOneInside) {
  TriangleMesh inward = test::icosphere(1.0, 2);
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(FastWindingNumber(inward)(Eigen::Vector3d(0.1, 0.2, 0.3)), -1.0, 0.05);
  // Signs by winding number count |w| >= 1/2 as inside, whatever the orientation.
  EXPECT_LT(ExactDistance(inward).signed_distance({0.1, 0.2, 0.3}, SignMethod::Winding), 0.0);
}

// Boundary edges (in one triangle only) of a welded mesh: where its holes are.
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boundary_edges(const TriangleMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[static_cast<std::size_t>(e)], b = t[static_cast<std::size_t>((e + 1) % 3)];
      ++count[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> edges;
  for (const auto& [edge, n] : count)
    if (n == 1) edges.emplace_back(mesh.vertices[edge.first], mesh.vertices[edge.second]);
  return edges;
}

double distance_to_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

TEST(WindingNumber, ElephantWithHolesAgreesWithTheClosedElephantAwayFromTheHoles) {
  const TriangleMesh closed = load_mesh(test::cgal_mesh("elephant"));
  const TriangleMesh holed = load_mesh(test::cgal_mesh("elephant-with-holes"));
  const auto holes = boundary_edges(holed);
  ASSERT_FALSE(holes.empty());
  EXPECT_TRUE(boundary_edges(closed).empty());
  const ExactDistance closed_exact(closed);
  const FastWindingNumber holed_winding(holed);
  const Aabb box = bounding_box(closed);
  const double diagonal = box.size().norm();
  int compared = 0, disagreements = 0, holed_pseudonormal_errors = 0;
  const ExactDistance holed_exact(holed);
  for (const Eigen::Vector3d& p : random_points(box, 4000, 5)) {
    // The two files are different triangulations of one surface: skip points too near the surface
    // for them to agree, and points near a hole, where the open mesh does not say what is inside.
    if (closed_exact.closest(p).distance < 0.01 * diagonal) continue;
    double to_hole = INFINITY;
    for (const auto& [a, b] : holes) to_hole = std::min(to_hole, distance_to_segment(p, a, b));
    if (to_hole < 0.1 * diagonal) continue;
    ++compared;
    const bool inside_closed = closed_exact.signed_distance(p, SignMethod::Pseudonormal) < 0.0;
    const bool inside_holed = std::abs(holed_winding(p)) >= 0.5;
    disagreements += inside_closed != inside_holed ? 1 : 0;
    holed_pseudonormal_errors += inside_closed != (holed_exact.signed_distance(p, SignMethod::Pseudonormal) < 0.0);
  }
  EXPECT_GT(compared, 500);
  EXPECT_EQ(disagreements, 0) << "of " << compared;
  RecordProperty("pseudonormal_sign_errors_on_the_open_mesh", holed_pseudonormal_errors);
}

}  // namespace
}  // namespace ts::sdf
