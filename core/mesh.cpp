#include "core/mesh.h"

namespace ts {

Aabb bounding_box(const TriangleMesh& mesh) {
  Aabb box;
  for (const auto& v : mesh.vertices) box.extend(v);
  return box;
}

double surface_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    area += 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
  }
  return area;
}

}  // namespace ts
