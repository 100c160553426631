#pragma once
// `tetrasand sample --fill`: interior particles for users who want a solid body, not only the
// surface layer. They sit on a face-centred cubic lattice (the densest sphere packing, every sphere
// touching 12 others) of nearest-neighbour distance 2 r, with a lattice point at the solid's centre
// of mass and cube edges along the mesh axes. A lattice point is kept when its exact signed distance
// to the mesh is phi <= -r: its sphere lies wholly inside the solid, and since the surface particles
// sit on the surface, its centre is at least r from every one of them. So the interior holds about
// V(phi <= -r) / (4 sqrt(2) r^3) particles (the cubic cell of edge 2 sqrt(2) r holds four).
#include <Eigen/Core>
#include <vector>

#include "core/mesh.h"
#include "sdf/exact_sdf.h"
#include "sdf/settings.h"

namespace ts::sampler {

// Lattice points per unit volume for radius r: 1 / (4 sqrt(2) r^3).
double interior_lattice_density(double radius);

// The kept lattice points, in a fixed order (z layer, y, x, basis point). `exact` holds the mesh;
// `sign` as the sampler's (winding: also open meshes). TBB-parallel over z layers.
std::vector<Eigen::Vector3d> fill_interior(const sdf::ExactDistance& exact, const Aabb& box,
                                           const Eigen::Vector3d& lattice_origin, double radius,
                                           sdf::SignMethod sign);

}  // namespace ts::sampler
