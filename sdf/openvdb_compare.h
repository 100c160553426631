#pragma once
// tetrasand's SDF against OpenVDB's meshToLevelSet, both against exact distance: statistics, since
// OpenVDB is itself approximate on non-convex meshes (up to about a voxel, and a few wrong signs
// next to the surface): exact distance decides who is right.
#include <openvdb/openvdb.h>

#include <string>

#include "core/mesh.h"
#include "sdf/grid.h"

namespace ts::sdf {

// OpenVDB's level set of the mesh at voxel size h [m] and half-width band [voxels]:
// tools::meshToLevelSet. renormalize = false runs the same conversion with DISABLE_RENORMALIZATION,
// for the bench's look at where OpenVDB's error comes from: its renormalisation pass (shift by -0.8
// voxel, one Godunov step, signed minimum, shift back) lowers by exactly one voxel every voxel within
// 0.8 voxel outside the surface that is a local maximum of the distance (a ridge between two nearby
// sheets), which is where its max error of exactly 1.000 voxel comes from (docs/benchmarks.md, sdf).
openvdb::FloatGrid::Ptr openvdb_level_set(const TriangleMesh& mesh, double h, double band, bool renormalize = true);

// The same conversion as a band for the sampler on a machine without a GPU: an index-space level set on
// `spec` (voxel (i, j, k) at coordinate spec.index_offset + (i, j, k), transform of voxel size 1, values
// in world units: what ScanConvertOptions::index_space_grid gives), half-width `band_voxels`. The mesh
// goes to voxel units in double before OpenVDB sees it, so any voxel size works; signs are OpenVDB's
// (closed meshes only: no pseudonormals, no winding number).
openvdb::FloatGrid::Ptr openvdb_index_level_set(const TriangleMesh& mesh, const GridSpec& spec,
                                                double band_voxels);

struct GridComparison {
  std::size_t voxels = 0;              // compared: |value| < band in either grid
  std::size_t sign_disagreements = 0;
  double mean = 0, p99 = 0, max = 0;   // |a - reference| [voxels]
};

// Compares `a` with `reference` over the voxels active with |value| < band_world [m] in either grid
// (where one grid has no active voxel its value is its background, +-band). Sign disagreements skip
// voxels the reference puts on the surface (|value| < 1e-4 voxel).
GridComparison compare_grids(const openvdb::FloatGrid& a, const openvdb::FloatGrid& reference, double voxel_size,
                             double band_world);

// tetrasand's GPU grid and OpenVDB's, each against the exact one, and against each other.
struct ThreeWayComparison {
  GridComparison gpu_vs_exact, openvdb_vs_exact, gpu_vs_openvdb;
};
ThreeWayComparison compare_with_exact(const openvdb::FloatGrid& gpu, const openvdb::FloatGrid& openvdb,
                                      const openvdb::FloatGrid& exact, double voxel_size, double band_world);

// The report `tetrasand sdf --compare-openvdb` prints.
std::string format_comparison(const GridComparison& gpu_vs_exact, const GridComparison& openvdb_vs_exact,
                              const GridComparison& gpu_vs_openvdb);
std::string format_comparison(const ThreeWayComparison& comparison);

}  // namespace ts::sdf
