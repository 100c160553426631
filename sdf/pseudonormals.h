#pragma once
// Angle-weighted pseudonormals (Baerentzen & Aanaes 2005): the sign of (p - q) . n, with q the closest
// point and n the pseudonormal of the feature (face, edge, vertex) holding q, classifies p exactly
// against a closed, consistently oriented manifold mesh. Computed once per mesh in double precision.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/mesh.h"

namespace ts::sdf {

struct Pseudonormals {
  std::vector<Eigen::Vector3d> face;                   // unit face normal per triangle
  std::vector<std::array<Eigen::Vector3d, 3>> edge;    // edge e runs from vertex e to vertex (e+1)%3
  std::vector<std::array<Eigen::Vector3d, 3>> vertex;  // per triangle corner
  std::size_t degenerate_triangles = 0;                // zero area: zero weight, normal of a neighbour or +z
};

Pseudonormals compute_pseudonormals(const TriangleMesh& mesh);

}  // namespace ts::sdf
