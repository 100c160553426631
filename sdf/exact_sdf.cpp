#include "sdf/exact_sdf.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

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

// The point of triangle (a, b, c) closest to p, by the Voronoi regions of its vertices, edges and
// face (Ericson, Real-Time Collision Detection, 5.1.5), in double. A degenerate triangle falls
// into a vertex or edge region, so no division by its zero area happens.
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  if (!std::isfinite(denom)) return a;  // all three vertices coincide
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace

struct ExactDistance::Tree {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> ids;  // triangle index in the mesh of each primitive
  AabbTree tree;
};

ExactDistance::ExactDistance(const TriangleMesh& mesh)
    : mesh_(mesh), normals_(compute_pseudonormals(mesh)), winding_(mesh), tree_(std::make_unique<Tree>()) {
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

ClosestPoint ExactDistance::closest_on(const Eigen::Vector3d& p, std::uint32_t triangle) const {
  const auto& t = mesh_.triangles[triangle];
  const Eigen::Vector3d &a = mesh_.vertices[t[0]], &b = mesh_.vertices[t[1]], &c = mesh_.vertices[t[2]];
  ClosestPoint out;
  out.point = closest_on_triangle(p, a, b, c);
  out.distance = (p - out.point).norm();
  out.triangle = triangle;
  classify(a, b, c, out.point, out);
  return out;
}

const Eigen::Vector3d& ExactDistance::feature_normal(const ClosestPoint& c) const {
  switch (c.feature) {
    case Feature::Face: return normals_.face[c.triangle];
    case Feature::Edge: return normals_.edge[c.triangle][static_cast<std::size_t>(c.index)];
    default: return normals_.vertex[c.triangle][static_cast<std::size_t>(c.index)];
  }
}

double ExactDistance::winding_number(const Eigen::Vector3d& p) const { return winding_(p); }

double ExactDistance::signed_distance(const Eigen::Vector3d& p, SignMethod method) const {
  return signed_distance(p, closest(p), method);
}

double ExactDistance::signed_distance(const Eigen::Vector3d& p, const ClosestPoint& c, SignMethod method) const {
  const bool inside = method == SignMethod::Winding ? std::abs(winding_number(p)) >= 0.5
                                                    : (p - c.point).dot(feature_normal(c)) < 0.0;
  return inside ? -c.distance : c.distance;
}

namespace {

// Triangles whose bounding box, grown by the band, reaches z slice k: only they can put a voxel of
// that slice inside the band, so only that slice's voxels under their boxes are queried.
std::vector<std::vector<std::uint32_t>> triangles_per_slice(const TriangleMesh& mesh, const GridSpec& spec,
                                                            double band) {
  std::vector<std::vector<std::uint32_t>> slices(static_cast<std::size_t>(spec.dims.z()));
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    double lo = INFINITY, hi = -INFINITY;
    for (auto v : mesh.triangles[t]) {
      lo = std::min(lo, mesh.vertices[v].z());
      hi = std::max(hi, mesh.vertices[v].z());
    }
    const double k_lo = std::ceil((lo - band - spec.origin.z()) / spec.voxel_size);
    const double k_hi = std::floor((hi + band - spec.origin.z()) / spec.voxel_size);
    for (int k = std::max(0, static_cast<int>(k_lo)); k <= std::min(spec.dims.z() - 1, static_cast<int>(k_hi)); ++k)
      slices[static_cast<std::size_t>(k)].push_back(t);
  }
  return slices;
}

struct BandVoxel {
  openvdb::Coord coord;
  float value;
};

// The band voxels of slice k, by a sweep over the slice's triangles (the CPU form of the scan
// conversion): each triangle visits the voxels of the slice within the band of its plane and under
// its xy box grown by the band, keeping the nearest triangle of each voxel; then each voxel's
// closest point on that triangle gives the distance, the feature and the sign. Equal distances go
// to the lowest triangle index (the slice's triangles are in index order), so threads do not
// change the result.
std::vector<BandVoxel> slice_band(const ExactDistance& exact, const TriangleMesh& mesh, const GridSpec& spec,
                                  const std::vector<std::uint32_t>& triangles, int k, double band, SignMethod sign) {
  const int nx = spec.dims.x(), ny = spec.dims.y();
  const std::size_t row = static_cast<std::size_t>(nx);
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<double> nearest_sq(row * static_cast<std::size_t>(ny), band * band);
  std::vector<std::uint32_t> nearest(nearest_sq.size(), kNone);
  const double z = spec.voxel_center(0, 0, k).z();
  for (std::uint32_t t : triangles) {
    const Eigen::Vector3d& a = mesh.vertices[mesh.triangles[t][0]];
    const Eigen::Vector3d& b = mesh.vertices[mesh.triangles[t][1]];
    const Eigen::Vector3d& c = mesh.vertices[mesh.triangles[t][2]];
    const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c) - Eigen::Vector3d::Constant(band);
    const Eigen::Vector3d hi = a.cwiseMax(b).cwiseMax(c) + Eigen::Vector3d::Constant(band);
    const Eigen::Vector3d vlo = spec.to_voxel(lo), vhi = spec.to_voxel(hi);
    const int i0 = std::max(0, static_cast<int>(std::ceil(vlo.x()))), i1 = std::min(nx - 1, static_cast<int>(std::floor(vhi.x())));
    const int j0 = std::max(0, static_cast<int>(std::ceil(vlo.y()))), j1 = std::min(ny - 1, static_cast<int>(std::floor(vhi.y())));
    // Only voxels within the band of the triangle's plane can be within the band of the triangle:
    // on each row that is an interval of x (when the plane is not parallel to x), which keeps a
    // large slanted triangle from visiting its whole box.
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double length = n.norm();
    const bool prune = length > 0 && std::abs(n.x()) > 1e-3 * length;
    if (prune) n /= length;
    for (int j = j0; j <= j1; ++j) {
      int from = i0, to = i1;
      if (prune) {
        const double y = spec.voxel_center(0, j, k).y();
        // n . (p - a) = 0 at x0; |n . (p - a)| < band for |x - x0| < band / |n.x|.
        const double x0 = a.x() - (n.y() * (y - a.y()) + n.z() * (z - a.z())) / n.x();
        const double reach = band / std::abs(n.x());
        const Eigen::Vector3d e = spec.to_voxel(Eigen::Vector3d(x0, y, z));
        const double half = reach / spec.voxel_size;
        from = std::max(from, static_cast<int>(std::ceil(e.x() - half)) - 1);
        to = std::min(to, static_cast<int>(std::floor(e.x() + half)) + 1);
      }
      for (int i = from; i <= to; ++i) {
        const Eigen::Vector3d p = spec.voxel_center(i, j, k);
        const double d_sq = (closest_on_triangle(p, a, b, c) - p).squaredNorm();
        const std::size_t v = static_cast<std::size_t>(i) + row * static_cast<std::size_t>(j);
        if (d_sq < nearest_sq[v]) {
          nearest_sq[v] = d_sq;
          nearest[v] = t;
        }
      }
    }
  }
  std::vector<BandVoxel> out;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::uint32_t t = nearest[static_cast<std::size_t>(i) + row * static_cast<std::size_t>(j)];
      if (t == kNone) continue;
      const Eigen::Vector3d p = spec.voxel_center(i, j, k);
      const ClosestPoint c = exact.closest_on(p, t);
      if (!(c.distance < band)) continue;
      out.push_back({openvdb::Coord(spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k),
                     static_cast<float>(exact.signed_distance(p, c, sign))});
    }
  return out;
}

openvdb::FloatGrid::Ptr empty_level_set(const GridSpec& spec, double band, bool index_space) {
  auto grid = openvdb::FloatGrid::create(static_cast<float>(band));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(index_space ? 1.0 : spec.voxel_size));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->setName("surface");
  return grid;
}

}  // namespace

openvdb::FloatGrid::Ptr exact_sdf_grid(const TriangleMesh& mesh, const GridSpec& spec, double band_voxels,
                                       SignMethod sign) {
  if (mesh.empty()) return empty_level_set(spec, band_voxels * spec.voxel_size, false);
  const ExactDistance exact(mesh);
  return exact_sdf_grid(exact, mesh, spec, band_voxels, sign);
}

openvdb::FloatGrid::Ptr exact_sdf_grid(const ExactDistance& exact, const TriangleMesh& mesh,
                                       const GridSpec& spec, double band_voxels, SignMethod sign,
                                       bool index_space) {
  const double band = band_voxels * spec.voxel_size;
  auto grid = empty_level_set(spec, band, index_space);
  if (mesh.empty()) return grid;
  const auto slices = triangles_per_slice(mesh, spec, band);
  std::vector<std::vector<BandVoxel>> voxels(slices.size());
  tbb::parallel_for(0, spec.dims.z(), [&](int k) {
    const auto slice = static_cast<std::size_t>(k);
    voxels[slice] = slice_band(exact, mesh, spec, slices[slice], k, band, sign);
  });
  // OpenVDB trees are not safe to write from several threads: the slices go in one after another.
  auto accessor = grid->getAccessor();
  for (const auto& slice : voxels)
    for (const BandVoxel& v : slice) accessor.setValue(v.coord, v.value);
  openvdb::tools::signedFloodFill(grid->tree());
  return grid;
}

void resign_by_winding_number(openvdb::FloatGrid& grid, const ExactDistance& exact, const GridSpec* index_space) {
  std::vector<std::pair<openvdb::Coord, float>> voxels;
  voxels.reserve(grid.activeVoxelCount());
  for (auto it = grid.cbeginValueOn(); it; ++it) voxels.emplace_back(it.getCoord(), *it);
  const auto world = [&](const openvdb::Coord& c) -> Eigen::Vector3d {
    if (index_space) {
      const Eigen::Vector3i& o = index_space->index_offset;
      return index_space->voxel_center(c.x() - o.x(), c.y() - o.y(), c.z() - o.z());
    }
    const openvdb::Vec3d p = grid.indexToWorld(c);
    return {p.x(), p.y(), p.z()};
  };
  tbb::parallel_for(std::size_t{0}, voxels.size(), [&](std::size_t i) {
    const bool inside = std::abs(exact.winding_number(world(voxels[i].first))) >= 0.5;
    voxels[i].second = inside ? -std::abs(voxels[i].second) : std::abs(voxels[i].second);
  });
  // OpenVDB trees are not safe to write from several threads.
  auto accessor = grid.getAccessor();
  for (const auto& [coord, value] : voxels) accessor.setValue(coord, value);
  openvdb::tools::signedFloodFill(grid.tree());
}

std::vector<float> exact_sdf_dense(const TriangleMesh& mesh, const GridSpec& spec, double band_voxels,
                                   SignMethod sign) {
  const auto grid = exact_sdf_grid(mesh, spec, band_voxels, sign);
  std::vector<float> dense(spec.voxel_count());
  auto accessor = grid->getConstAccessor();
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i)
        dense[spec.linear_index(i, j, k)] = accessor.getValue(
            openvdb::Coord(spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k));
  return dense;
}

}  // namespace ts::sdf
