#include "sampler/surface_points.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ts::sampler {

AreaTable::AreaTable(const TriangleMesh& mesh) : mesh_(&mesh) {
  cumulative_.reserve(mesh.triangles.size());
  double sum = 0.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d& a = mesh.vertices[tri[0]];
    const double area = 0.5 * (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a).norm();
    if (area > 0.0) last_positive_ = static_cast<std::uint32_t>(t);
    sum += area;
    cumulative_.push_back(sum);
  }
  if (!(sum > 0.0) || !std::isfinite(sum)) {
    throw InputError("the mesh has no surface to sample (no triangle of positive, finite area)");
  }
}

std::uint32_t AreaTable::pick_triangle(double u) const {
  // upper_bound skips zero-area triangles: their cumulative value equals their predecessor's.
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), u * total_area());
  if (it == cumulative_.end()) return last_positive_;
  return static_cast<std::uint32_t>(it - cumulative_.begin());
}

Eigen::Vector3d AreaTable::point_in_triangle(std::uint32_t t, double u1, double u2) const {
  const auto& tri = mesh_->triangles[t];
  const double r = std::sqrt(u1);
  return (1.0 - r) * mesh_->vertices[tri[0]] + r * (1.0 - u2) * mesh_->vertices[tri[1]] +
         r * u2 * mesh_->vertices[tri[2]];
}

Eigen::Vector3d AreaTable::face_normal(std::uint32_t t) const {
  const auto& tri = mesh_->triangles[t];
  const Eigen::Vector3d& a = mesh_->vertices[tri[0]];
  return (mesh_->vertices[tri[1]] - a).cross(mesh_->vertices[tri[2]] - a).normalized();
}

SurfacePoints sample_surface_points(const AreaTable& table, std::size_t count, std::mt19937_64& rng) {
  SurfacePoints out;
  out.positions.reserve(count);
  out.triangles.reserve(count);
  out.normals.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t t = table.pick_triangle(uniform01(rng));
    const double u1 = uniform01(rng);
    const double u2 = uniform01(rng);
    out.positions.push_back(table.point_in_triangle(t, u1, u2));
    out.triangles.push_back(t);
    out.normals.push_back(table.face_normal(t));
  }
  return out;
}

SurfacePoints sample_surface_points(const TriangleMesh& mesh, std::size_t count, std::mt19937_64& rng) {
  return sample_surface_points(AreaTable(mesh), count, rng);
}

}  // namespace ts::sampler
