#include "sdf/exact_sdf.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace ts::sdf {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Eigen::Vector3d to_eigen(const Point& p) { return {p.x(), p.y(), p.z()}; }

// Which feature of triangle (a, b, c) holds q: from q's barycentric coordinates, with a tolerance
// relative to the triangle's size so that points on an edge are not called "face" by rounding.
void classify(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& q,
              ClosestPoint& out) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  if (!(area2 > 0.0)) {  // degenerate: nearest vertex decides
    const double da = (q - a).squaredNorm(), db = (q - b).squaredNorm(), dc = (q - c).squaredNorm();
    out.feature = Feature::Vertex;
    out.index = da <= db && da <= dc ? 0 : (db <= dc ? 1 : 2);
    return;
  }
  const double w[3] = {(b - q).cross(c - q).dot(n) / area2, (c - q).cross(a - q).dot(n) / area2,
                       (a - q).cross(b - q).dot(n) / area2};
  constexpr double tolerance = 1e-9;
  int zero = 0, last_zero = -1, last_nonzero = -1;
  for (int k = 0; k < 3; ++k) {
    if (w[k] <= tolerance) {
      ++zero;
      last_zero = k;
    } else {
      last_nonzero = k;
    }
  }
  if (zero == 0) {
    out.feature = Feature::Face;
  } else if (zero == 1) {
    // Weight of vertex k vanishes: q is on the opposite edge, from vertex k+1 to k+2.
    out.feature = Feature::Edge;
    out.index = (last_zero + 1) % 3;
  } else {
    out.feature = Feature::Vertex;
    out.index = last_nonzero < 0 ? 0 : last_nonzero;
  }
}

// Signed solid angle of triangle (a, b, c) seen from p (van Oosterom & Strackee 1983).
double solid_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return 2.0 * std::atan2(numerator, denominator);
}

}  // namespace

struct ExactDistance::Tree {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> ids;  // triangle index in the mesh of each primitive
  AabbTree tree;
};

ExactDistance::ExactDistance(const TriangleMesh& mesh)
    : mesh_(mesh), normals_(compute_pseudonormals(mesh)), tree_(std::make_unique<Tree>()) {
  tree_->triangles.reserve(mesh.triangle_count());
  for (const auto& t : mesh.triangles) {
    auto point = [&](std::uint32_t v) { return Point(mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z()); };
    tree_->triangles.emplace_back(point(t[0]), point(t[1]), point(t[2]));
  }
  tree_->tree.insert(tree_->triangles.cbegin(), tree_->triangles.cend());
  tree_->tree.accelerate_distance_queries();
}

ExactDistance::~ExactDistance() = default;

ClosestPoint ExactDistance::closest(const Eigen::Vector3d& p) const {
  const auto hit = tree_->tree.closest_point_and_primitive(Point(p.x(), p.y(), p.z()));
  ClosestPoint out;
  out.point = to_eigen(hit.first);
  out.distance = (p - out.point).norm();
  out.triangle = static_cast<std::uint32_t>(hit.second - tree_->triangles.cbegin());
  const auto& t = mesh_.triangles[out.triangle];
  classify(mesh_.vertices[t[0]], mesh_.vertices[t[1]], mesh_.vertices[t[2]], out.point, out);
  return out;
}

const Eigen::Vector3d& ExactDistance::feature_normal(const ClosestPoint& c) const {
  switch (c.feature) {
    case Feature::Face: return normals_.face[c.triangle];
    case Feature::Edge: return normals_.edge[c.triangle][static_cast<std::size_t>(c.index)];
    default: return normals_.vertex[c.triangle][static_cast<std::size_t>(c.index)];
  }
}

double ExactDistance::winding_number(const Eigen::Vector3d& p) const {
  // Direct sum over all triangles: exact, O(triangles) per query.
  double total = 0.0;
  for (const auto& t : mesh_.triangles)
    total += solid_angle(mesh_.vertices[t[0]] - p, mesh_.vertices[t[1]] - p, mesh_.vertices[t[2]] - p);
  return total / (4.0 * M_PI);
}

double ExactDistance::signed_distance(const Eigen::Vector3d& p, SignMethod method) const {
  const ClosestPoint c = closest(p);
  bool inside;
  if (method == SignMethod::Winding) {
    inside = winding_number(p) >= 0.5;
  } else {
    inside = (p - c.point).dot(feature_normal(c)) < 0.0;
  }
  return inside ? -c.distance : c.distance;
}

openvdb::FloatGrid::Ptr exact_sdf_grid(const TriangleMesh& mesh, const GridSpec& spec, double band_voxels,
                                       SignMethod sign) {
  const ExactDistance exact(mesh);
  const double band = band_voxels * spec.voxel_size;
  std::vector<float> values(spec.voxel_count(), std::numeric_limits<float>::infinity());
  tbb::parallel_for(0, spec.dims.z(), [&](int k) {
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const Eigen::Vector3d p = spec.voxel_center(i, j, k);
        // Cheap rejection first: only voxels within the band need a sign.
        const ClosestPoint c = exact.closest(p);
        if (c.distance >= band) continue;
        values[spec.linear_index(i, j, k)] = static_cast<float>(exact.signed_distance(p, sign));
      }
  });
  auto grid = openvdb::FloatGrid::create(static_cast<float>(band));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(spec.voxel_size));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->setName("surface");
  auto accessor = grid->getAccessor();
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const float v = values[spec.linear_index(i, j, k)];
        if (std::isfinite(v))
          accessor.setValue(openvdb::Coord(spec.index_offset.x() + i, spec.index_offset.y() + j,
                                           spec.index_offset.z() + k), v);
      }
  openvdb::tools::signedFloodFill(grid->tree());
  return grid;
}

}  // namespace ts::sdf
