#pragma once
// The voxel grid every SDF path (GPU scan conversion, CPU exact, OpenVDB) samples. Voxel (i,j,k)'s
// centre is at origin + voxel_size * (i,j,k); this is exactly OpenVDB's index space under the
// linear transform make_transform() returns, so grids from all three paths line up voxel for voxel.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "core/mesh.h"
#include "sdf/settings.h"

namespace ts::sdf {

struct GridSpec {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // world position of voxel (0,0,0)'s centre [m]
  double voxel_size = 0.0;                             // edge of one voxel [m]
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();      // voxel counts along x, y, z
  // OpenVDB index of voxel (0,0,0); origin == voxel_size * index_offset, so the VDB transform is a
  // plain scale (openvdb::math::Transform::createLinearTransform(voxel_size)), the one meshToLevelSet uses.
  Eigen::Vector3i index_offset = Eigen::Vector3i::Zero();

  std::size_t voxel_count() const {
    return static_cast<std::size_t>(dims.x()) * static_cast<std::size_t>(dims.y()) *
           static_cast<std::size_t>(dims.z());
  }
  std::size_t linear_index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims.x()) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(dims.y()) * static_cast<std::size_t>(k));
  }
  Eigen::Vector3d voxel_center(int i, int j, int k) const {
    return origin + voxel_size * Eigen::Vector3d(i, j, k);
  }
  // World point -> continuous voxel coordinates (voxel centres at integers).
  Eigen::Vector3d to_voxel(const Eigen::Vector3d& world) const { return (world - origin) / voxel_size; }
};

// The grid for a bounding box: voxel size from the settings, index_offset = floor(min / h) - padding,
// dims covering max + padding. Throws ts::InputError for a non-finite or empty box, a non-positive
// voxel size or resolution, a band below one voxel, or a grid above settings.max_voxels (the
// message names the smallest voxel size that fits).
GridSpec make_grid(const Aabb& box, const SdfSettings& settings);

}  // namespace ts::sdf
