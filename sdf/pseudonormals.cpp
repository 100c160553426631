#include "sdf/pseudonormals.h"

#include <cmath>
#include <unordered_map>

namespace ts::sdf {
namespace {

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

double corner_angle(const Eigen::Vector3d& at, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d u = p - at, v = q - at;
  // atan2 of |u x v| and u.v stays accurate for angles near 0 and pi, unlike acos.
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

}  // namespace

Pseudonormals compute_pseudonormals(const TriangleMesh& mesh) {
  const std::size_t n = mesh.triangle_count();
  Pseudonormals out;
  out.face.resize(n);
  out.edge.resize(n);
  out.vertex.resize(n);

  std::vector<Eigen::Vector3d> area_vectors(n);
  for (std::size_t t = 0; t < n; ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d& a = mesh.vertices[tri[0]];
    area_vectors[t] = (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a);
    const double length = area_vectors[t].norm();
    if (length > 0.0 && std::isfinite(length)) {
      out.face[t] = area_vectors[t] / length;
    } else {
      out.face[t] = Eigen::Vector3d::UnitZ();
      ++out.degenerate_triangles;
    }
  }
  auto usable = [&](std::size_t t) {
    const double length = area_vectors[t].norm();
    return length > 0.0 && std::isfinite(length);
  };

  // Vertex pseudonormal: incident face normals weighted by the incident angle.
  std::vector<Eigen::Vector3d> vertex_sum(mesh.vertex_count(), Eigen::Vector3d::Zero());
  for (std::size_t t = 0; t < n; ++t) {
    if (!usable(t)) continue;
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const double angle = corner_angle(mesh.vertices[tri[k]], mesh.vertices[tri[(k + 1) % 3]],
                                        mesh.vertices[tri[(k + 2) % 3]]);
      vertex_sum[tri[k]] += angle * out.face[t];
    }
  }
  // Edge pseudonormal: the sum of the (two, on a manifold) incident face normals.
  std::unordered_map<std::uint64_t, Eigen::Vector3d> edge_sum;
  edge_sum.reserve(3 * n);
  for (std::size_t t = 0; t < n; ++t) {
    if (!usable(t)) continue;
    const auto& tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      auto [it, inserted] = edge_sum.try_emplace(edge_key(tri[e], tri[(e + 1) % 3]), Eigen::Vector3d::Zero());
      it->second += out.face[t];
    }
  }
  auto normalized_or = [](const Eigen::Vector3d& v, const Eigen::Vector3d& fallback) {
    const double length = v.norm();
    return length > 1e-300 ? Eigen::Vector3d(v / length) : fallback;
  };
  for (std::size_t t = 0; t < n; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      out.vertex[t][static_cast<std::size_t>(k)] = normalized_or(vertex_sum[tri[k]], out.face[t]);
      const auto it = edge_sum.find(edge_key(tri[k], tri[(k + 1) % 3]));
      out.edge[t][static_cast<std::size_t>(k)] =
          it == edge_sum.end() ? out.face[t] : normalized_or(it->second, out.face[t]);
    }
  }
  return out;
}

}  // namespace ts::sdf
