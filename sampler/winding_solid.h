#pragma once
// The solid of a mesh that does not enclose a volume by itself (holes, non-manifold edges), as the
// generalised winding number defines it: the points where |w| >= 1/2 (sdf/winding_number.h). Its
// mass properties cannot come from the divergence theorem, which needs a closed surface, so they are
// integrated over an adaptive octree of cells:
//  - a cell whose centre is farther from the mesh than its half diagonal is wholly inside or outside,
//    by w at its centre, when that w is within 0.02 of an integer (as everywhere off a closed
//    surface) or else when its eight corners lie on the same side of |w| = 1/2 as its centre (the
//    |w| = 1/2 surface that spans a hole is smooth, so a cell it does not separate at those nine
//    points it misses);
//  - other cells are split, down to cells of edge `cell`; such a finest cell counts the fraction
//    clamp(1/2 - phi / cell, 0, 1) of its volume, phi being the exact distance to the mesh signed by
//    the winding number at its centre (exact for a face parallel to the cell's sides, first order
//    in general). The inertia of each cell is that of a cube of its size about its centre.
// Measured on closed meshes against the divergence theorem at the default cell (longest side / 128):
// see tests/sampler/winding_solid_test.cpp and docs/body-format.md.
#include <cstddef>

#include "core/mass_properties.h"
#include "core/mesh.h"
#include "sdf/exact_sdf.h"

namespace ts::sampler {

inline constexpr int kDefaultWindingCellsAlongLongestSide = 128;

struct WindingSolid {
  MassProperties mass;          // density, volume, mass, centre of mass, inertia, principal frame
  double cell = 0.0;            // edge of the finest cells [m]
  std::size_t boundary_cells = 0;  // finest cells the surface or the |w| = 1/2 surface crosses
};

// `exact` must hold `mesh`. cell <= 0: longest bounding-box side / 128. Throws InputError when the
// region is empty (no point has |w| >= 1/2: the mesh encloses nothing, or it is inside out).
// Deterministic (cells are summed in a fixed order), TBB-parallel.
WindingSolid winding_mass_properties(const TriangleMesh& mesh, const sdf::ExactDistance& exact, double density,
                                     double cell = 0.0);

}  // namespace ts::sampler
