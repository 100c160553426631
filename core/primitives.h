#pragma once
// Closed, outward-oriented meshes made in code: the bundled assets (tools/make_assets.cpp) and tests.
#include <Eigen/Core>

#include "core/mesh.h"

namespace ts {

// Axis-aligned box from lo to hi [m]: 8 vertices, 12 triangles.
TriangleMesh make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);
// Box of edge lengths `size` [m] centred at the origin.
TriangleMesh make_box(const Eigen::Vector3d& size);
// Icosahedron subdivided `subdivisions` times (20 * 4^s triangles), vertices on the sphere [m].
TriangleMesh make_icosphere(double radius, int subdivisions);
// Torus about the z axis: major radius R, minor radius r [m], nu x nv quads split in two.
TriangleMesh make_torus(double major_radius, double minor_radius, int nu, int nv);
// A tube of radius r along the trefoil knot (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t) * scale [m]
// (the thesis's sampler example), with rotation-minimising frames so the tube closes without twist.
TriangleMesh make_trefoil_tube(double scale, double tube_radius, int n_along, int n_around);
// A thin rectangular plate sx x sy x thickness [m] centred at the origin, subdivided nx x ny on its
// large faces so that it is not only 12 long slivers.
TriangleMesh make_plate(double sx, double sy, double thickness, int nx, int ny);

}  // namespace ts
