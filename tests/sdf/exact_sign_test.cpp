// Signs of the exact SDF on real closed meshes (libcgal-demo), judged by CGAL's Side_of_triangle_mesh
// (ray parity with exact predicates): a reference independent of pseudonormals and winding numbers.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "core/mesh_io.h"
#include "sdf/exact_sdf.h"
#include "sdf/pseudonormals.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

SurfaceMesh to_surface_mesh(const TriangleMesh& mesh) {
  SurfaceMesh out;
  std::vector<SurfaceMesh::Vertex_index> vertices;
  vertices.reserve(mesh.vertex_count());
  for (const auto& v : mesh.vertices) vertices.push_back(out.add_vertex(Kernel::Point_3(v.x(), v.y(), v.z())));
  for (const auto& t : mesh.triangles) out.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]);
  return out;
}

struct SignTally {
  int compared = 0, pseudonormal_errors = 0, winding_errors = 0;
  int off_face = 0;  // compared points whose closest feature is an edge or a vertex
};

// Signs at `points` against CGAL's ray parity, except points within `skip` of the surface (there a
// point's side depends on rounding in either method) and points CGAL finds on the boundary.
SignTally tally_signs(const TriangleMesh& mesh, const std::vector<Eigen::Vector3d>& points, double skip) {
  const SurfaceMesh surface = to_surface_mesh(mesh);
  EXPECT_EQ(surface.number_of_faces(), mesh.triangle_count()) << "not manifold, so not a valid reference";
  const CGAL::Side_of_triangle_mesh<SurfaceMesh, Kernel> side(surface);
  const ExactDistance exact(mesh);
  SignTally tally;
  for (const Eigen::Vector3d& p : points) {
    const ClosestPoint c = exact.closest(p);
    if (c.distance < skip) continue;
    const CGAL::Bounded_side reference = side(Kernel::Point_3(p.x(), p.y(), p.z()));
    if (reference == CGAL::ON_BOUNDARY) continue;
    const bool inside = reference == CGAL::ON_BOUNDED_SIDE;
    ++tally.compared;
    tally.off_face += c.feature != Feature::Face;
    tally.pseudonormal_errors += (exact.signed_distance(p, c, SignMethod::Pseudonormal) < 0.0) != inside;
    tally.winding_errors += (exact.signed_distance(p, c, SignMethod::Winding) < 0.0) != inside;
  }
  return tally;
}

// Uniform in the bounding box grown by 10 % on each side.
std::vector<Eigen::Vector3d> box_points(const TriangleMesh& mesh, int count) {
  const Aabb box = bounding_box(mesh);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-0.1, 1.1);
  std::vector<Eigen::Vector3d> points;
  for (int n = 0; n < count; ++n)
    points.push_back(box.min + Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(box.size()));
  return points;
}

// Near the surface: a third of the points off a random point of a random triangle in a random
// direction; a third off a point of one of its edges and a third off one of its corners, along that
// feature's pseudonormal (either way) tilted a little at random. Off a smooth surface a random
// direction almost always finds a face closest; along the feature's normal it finds the edge or the
// vertex, so their pseudonormals are tested too.
std::vector<Eigen::Vector3d> near_surface_points(const TriangleMesh& mesh, int count, double offset) {
  const Pseudonormals normals = compute_pseudonormals(mesh);
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g;
  std::uniform_int_distribution<std::size_t> pick(0, mesh.triangle_count() - 1);
  std::vector<Eigen::Vector3d> points;
  for (int n = 0; n < count; ++n) {
    const std::size_t t = pick(rng);
    const auto& tri = mesh.triangles[t];
    double a = u(rng), b = u(rng);
    if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
    const Eigen::Vector3d noise = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const double side = u(rng) < 0.5 ? -1.0 : 1.0;
    Eigen::Vector3d direction = noise;
    if (n % 3 == 1) {
      b = 0.0;  // on the edge v0-v1
      direction = (side * normals.edge[t][0] + 0.2 * noise).normalized();
    } else if (n % 3 == 2) {
      a = 0.0, b = 0.0;  // on the corner v0
      direction = (side * normals.vertex[t][0] + 0.2 * noise).normalized();
    }
    const Eigen::Vector3d on = mesh.vertices[tri[0]] + a * (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]) +
                               b * (mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
    points.push_back(on + offset * direction);
  }
  return points;
}

void expect_signs_match_cgal(const std::string& name) {
  const TriangleMesh mesh = load_mesh(test::cgal_mesh(name));
  const double diagonal = bounding_box(mesh).size().norm();
  const SignTally far = tally_signs(mesh, box_points(mesh, 2000), 1e-4 * diagonal);
  EXPECT_GT(far.compared, 1800) << name;
  EXPECT_EQ(far.pseudonormal_errors, 0) << name << ": of " << far.compared;
  EXPECT_EQ(far.winding_errors, 0) << name << ": of " << far.compared;
  const SignTally near = tally_signs(mesh, near_surface_points(mesh, 2000, 1e-3 * diagonal), 1e-7 * diagonal);
  EXPECT_GT(near.compared, 1800) << name;
  EXPECT_GT(near.off_face, 400) << name << ": too few points nearest an edge or vertex to test their normals";
  EXPECT_EQ(near.pseudonormal_errors, 0) << name << ": of " << near.compared;
  EXPECT_EQ(near.winding_errors, 0) << name << ": of " << near.compared;
}

TEST(ExactSigns, ElephantSignsMatchCgalSideOfTriangleMesh) { expect_signs_match_cgal("elephant"); }

TEST(ExactSigns, KnotSignsMatchCgalSideOfTriangleMesh) { expect_signs_match_cgal("knot1"); }

}  // namespace
}  // namespace ts::sdf
