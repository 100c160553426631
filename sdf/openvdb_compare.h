#pragma once
// tetrasand's SDF against OpenVDB's meshToLevelSet, both against exact distance: statistics, since
// OpenVDB is itself approximate on non-convex meshes (up to about a voxel, and a few wrong signs
// next to the surface): exact distance decides who is right.
#include <openvdb/openvdb.h>

#include <string>

#include "core/mesh.h"

namespace ts::sdf {

// OpenVDB's level set of the mesh at voxel size h [m] and half-width band [voxels].
openvdb::FloatGrid::Ptr openvdb_level_set(const TriangleMesh& mesh, double h, double band);

struct GridComparison {
  std::size_t voxels = 0;              // compared: |value| < band in the reference
  std::size_t sign_disagreements = 0;
  double mean = 0, p99 = 0, max = 0;   // |a - reference| [voxels]
};

// Compares `a` with `reference` over the reference's band voxels (|value| < band_world).
GridComparison compare_grids(const openvdb::FloatGrid& a, const openvdb::FloatGrid& reference, double voxel_size,
                             double band_world);

// The report `tetrasand sdf --compare-openvdb` prints.
std::string format_comparison(const GridComparison& gpu_vs_exact, const GridComparison& openvdb_vs_exact,
                              const GridComparison& gpu_vs_openvdb);

}  // namespace ts::sdf
