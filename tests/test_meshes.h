#pragma once
// Small closed meshes built in code (core/primitives.h), for tests that must not depend on files.
#include <Eigen/Core>

#include <cmath>

#include "core/primitives.h"
#include "sdf/grid.h"

namespace ts::test {

inline TriangleMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) { return make_box(lo, hi); }
inline TriangleMesh icosphere(double radius, int subdivisions) { return make_icosphere(radius, subdivisions); }

// `part` moved by `offset` [m] and appended to `mesh` as another shell.
inline void append_shell(TriangleMesh& mesh, const TriangleMesh& part, const Eigen::Vector3d& offset) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const auto& v : part.vertices) mesh.vertices.push_back(v + offset);
  for (const auto& t : part.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

// A grid of voxel `h` around the mesh's bounding box with `padding` voxels to spare on each side.
inline sdf::GridSpec grid_around(const TriangleMesh& mesh, double h, int padding) {
  Eigen::Vector3d lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const auto& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  sdf::GridSpec s;
  s.voxel_size = h;
  for (int a = 0; a < 3; ++a) {
    s.index_offset[a] = static_cast<int>(std::floor(lo[a] / h)) - padding;
    s.dims[a] = static_cast<int>(std::ceil(hi[a] / h)) + padding - s.index_offset[a] + 1;
  }
  s.origin = h * s.index_offset.cast<double>();
  return s;
}

}  // namespace ts::test
