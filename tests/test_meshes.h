#pragma once
// Small closed meshes built in code (core/primitives.h), for tests that must not depend on files.
#include <Eigen/Core>

#include "core/primitives.h"

namespace ts::test {

inline TriangleMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) { return make_box(lo, hi); }
inline TriangleMesh icosphere(double radius, int subdivisions) { return make_icosphere(radius, subdivisions); }

}  // namespace ts::test
