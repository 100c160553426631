#include "sim/grain.h"

#include <cassert>
#include <cmath>
#include <numbers>

namespace ts::sim {

GrainShape make_tetrahedral_grain(double radius, double edge, double density) {
  assert(radius > 0 && edge > 0 && density > 0);
  GrainShape g;
  g.particle_radius = radius;
  g.edge = edge;
  g.centre_distance = edge * std::sqrt(3.0 / 8.0);
  // Alternate corners of a cube: a regular tetrahedron whose centroid is the origin.
  const std::array<Eigen::Vector3d, 4> corners = {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1),
                                                  Eigen::Vector3d(-1, 1, -1), Eigen::Vector3d(-1, -1, 1)};
  for (int i = 0; i < 4; ++i) g.offsets[i] = corners[i].normalized() * g.centre_distance;
  g.mass = density * 4.0 * (4.0 / 3.0) * std::numbers::pi * radius * radius * radius;
  g.inertia = g.mass * (2.0 / 3.0 * g.centre_distance * g.centre_distance + 0.4 * radius * radius);
  g.bounding_radius = g.centre_distance + radius;
  return g;
}

}  // namespace ts::sim
