#pragma once
// The accuracy end of the SDF trade and the ground truth in tests: exact closest points in double
// precision, signed by angle-weighted pseudonormals or by the generalised winding number (robust to
// holes). Single points go through a CGAL AABB tree; a grid is swept triangle by triangle (the
// CPU form of the scan conversion: each triangle visits the voxels within the band of its plane),
// TBB-parallel over z slices, which gives the tree's field 4-11x faster (docs/benchmarks.md,
// "sample fixed costs").
#include <openvdb/openvdb.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/mesh.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/settings.h"
#include "sdf/winding_number.h"

namespace ts::sdf {

enum class Feature { Face, Edge, Vertex };

struct ClosestPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // m, on the mesh
  double distance = 0.0;                            // m, unsigned
  std::uint32_t triangle = 0;
  Feature feature = Feature::Face;
  int index = 0;  // edge e (vertex e -> e+1) or vertex k of the triangle
};

class ExactDistance {
 public:
  explicit ExactDistance(const TriangleMesh& mesh);
  ~ExactDistance();
  ExactDistance(const ExactDistance&) = delete;
  ExactDistance& operator=(const ExactDistance&) = delete;

  ClosestPoint closest(const Eigen::Vector3d& p) const;
  // The closest point to p on one given triangle of the mesh, its feature classified as closest() does.
  ClosestPoint closest_on(const Eigen::Vector3d& p, std::uint32_t triangle) const;
  double signed_distance(const Eigen::Vector3d& p, SignMethod method) const;
  // The same, reusing a closest point already found for p.
  double signed_distance(const Eigen::Vector3d& p, const ClosestPoint& c, SignMethod method) const;
  // Generalised winding number (sdf/winding_number.h, hierarchical): about 1 inside, 0 outside,
  // fractional near holes; |w| >= 1/2 counts as inside (an inward-oriented closed mesh gives -1).
  double winding_number(const Eigen::Vector3d& p) const;
  // The outward pseudonormal of the feature holding a closest point.
  const Eigen::Vector3d& feature_normal(const ClosestPoint& c) const;
  const Pseudonormals& pseudonormals() const { return normals_; }

 private:
  struct Tree;
  TriangleMesh mesh_;  // a copy: callers may pass a temporary
  Pseudonormals normals_;
  FastWindingNumber winding_;
  std::unique_ptr<Tree> tree_;
};

// Every voxel with |d| < band * h, in world units, as an OpenVDB level set (background band * h,
// transform createLinearTransform(h), coordinates index_offset + (i, j, k), name "surface"); voxels
// outside the band get +-band by a signed flood fill. TBB-parallel over z slices; each slice keeps
// the nearest of its triangles per voxel (equal distances: the lowest index), so the field does not
// depend on the thread count.
openvdb::FloatGrid::Ptr exact_sdf_grid(const TriangleMesh& mesh, const GridSpec& spec, double band_voxels,
                                       SignMethod sign);
// The same from a tree already built over `mesh` (`exact`'s own mesh). index_space: transform of voxel
// size 1, values still in world units (any voxel size; what sdf::SparseField reads, as
// ScanConvertOptions::index_space_grid).
openvdb::FloatGrid::Ptr exact_sdf_grid(const ExactDistance& exact, const TriangleMesh& mesh,
                                       const GridSpec& spec, double band_voxels, SignMethod sign,
                                       bool index_space = false);

// Re-signs every active voxel of a level set (world units) by the generalised winding number of
// `exact`'s mesh, |w| >= 1/2 inside, and floods the signs outward again (OpenVDB signedFloodFill):
// the sign method for open meshes, where pseudonormals are wrong next to the holes. Distances are
// kept. TBB-parallel over the voxels. `index_space`: the grid is an index-space one (transform of voxel
// size 1, as exact_sdf_grid's index_space and ScanConvertOptions::index_space_grid make): voxel
// positions come from this spec (spec.origin + h * (coord - index_offset)), not from the transform.
void resign_by_winding_number(openvdb::FloatGrid& grid, const ExactDistance& exact,
                              const GridSpec* index_space = nullptr);

// The same field, every voxel of `spec` (spec.linear_index order), clamped to +-band * h [m]: the
// flood-filled level set read back densely, for comparisons with sdf::DenseSdf.
std::vector<float> exact_sdf_dense(const TriangleMesh& mesh, const GridSpec& spec, double band_voxels,
                                   SignMethod sign);

}  // namespace ts::sdf
