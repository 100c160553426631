#pragma once
// The accuracy end of the SDF trade and the ground truth in tests: exact closest points through a
// CGAL AABB tree in double precision, signed by angle-weighted pseudonormals or by the generalised
// winding number (robust to holes), TBB-parallel over the grid.
#include <openvdb/openvdb.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/mesh.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/settings.h"

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
  double signed_distance(const Eigen::Vector3d& p, SignMethod method) const;
  // Generalised winding number (Jacobson et al. 2013): about 1 inside, 0 outside, fractional near holes.
  double winding_number(const Eigen::Vector3d& p) const;
  // The outward pseudonormal of the feature holding a closest point.
  const Eigen::Vector3d& feature_normal(const ClosestPoint& c) const;
  const Pseudonormals& pseudonormals() const { return normals_; }

 private:
  struct Tree;
  const TriangleMesh& mesh_;
  Pseudonormals normals_;
  std::unique_ptr<Tree> tree_;
};

// Every voxel with |d| < band * h, in world units, as an OpenVDB level set (background band * h,
// transform createLinearTransform(h), name "surface"); voxels outside the band get +-band by a
// signed flood fill.
openvdb::FloatGrid::Ptr exact_sdf_grid(const TriangleMesh& mesh, const GridSpec& spec, double band_voxels,
                                       SignMethod sign);

}  // namespace ts::sdf
