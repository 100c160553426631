#pragma once
// Small closed meshes built in code, for tests that must not depend on file loading.
#include <Eigen/Core>

#include "core/mesh.h"

namespace ts::test {

// Axis-aligned box, 12 outward triangles.
TriangleMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);
// Icosahedron subdivided `subdivisions` times, vertices on the sphere of `radius` about the origin.
TriangleMesh icosphere(double radius, int subdivisions);

}  // namespace ts::test
