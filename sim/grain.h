#pragma once
// The sand grain: a rigid regular tetrahedron of four equal solid spheres (thesis 3.1, 3.3.2).
#include <Eigen/Core>

#include <array>

namespace ts::sim {

struct GrainShape {
  double particle_radius = 0;  // r, m
  double edge = 0;             // a, m: distance between sphere centres (2r = touching spheres)
  double centre_distance = 0;  // R = a sqrt(3/8), m: sphere centre to grain centre
  std::array<Eigen::Vector3d, 4> offsets;  // m, body frame (origin at the centre of mass)
  double mass = 0;             // kg
  double inertia = 0;          // kg m^2: the tensor is isotropic, I = inertia * Id
  double bounding_radius = 0;  // m: R + r, radius of the sphere around the centre holding the grain
};

// Mass convention: four full spheres, m = density * 4 * (4/3) pi r^3, even when a < 2r makes them
// overlap (the overlapping lens is counted twice). This is what LAMMPS and LIGGGHTS do for clumps
// built from per-atom masses, so bundled peer comparisons see the same masses. Inertia: each
// sphere contributes 2/5 (m/4) r^2 about its own centre plus (m/4) R^2 (Id - u u^T); the four
// vertex directions u sum to 4/3 Id, so I = m (2/3 R^2 + 2/5 r^2) Id.
// Requires radius > 0, edge > 0, density > 0 (kg/m^3); asserts (callers validate user input).
GrainShape make_tetrahedral_grain(double radius, double edge, double density);

}  // namespace ts::sim
