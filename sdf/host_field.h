#pragma once
// The narrow-band SDF where the CPU reads it: the same NanoVDB float level set that sdf::SparseField
// uploads (sdf/sparse_field.h), held on the host only (no GL buffer, so no storage-block limit and no
// GL context), read with the weights and the gradient of shaders/common/sparse_field.glsl: trilinear
// values, central differences half a voxel either side, normalised. The CPU relaxation
// (sampler/cpu_relaxer.h) reads it; the GPU relaxation reads the uploaded copy.
#include <nanovdb/NanoVDB.h>
#include <Eigen/Core>

#include <cstddef>

#include "sdf/grid.h"
#include "sdf/sparse_field.h"

namespace ts::sdf {

// A NanoVDB read accessor: it caches the nodes of the last read, so neighbouring reads skip the tree
// walk. Not thread-safe: one per thread (HostField::accessor()).
using FieldAccessor = nanovdb::DefaultReadAccessor<float>;

// The value of the grid at grid-local position `x` [voxels] (voxel (0,0,0) of the grid spec at 0, at
// NanoVDB index `index_offset`) by trilinear interpolation [world units]: the weights of
// field_trilinear in shaders/common/sparse_field.glsl, in the same order, in double. Off the band the
// background's +-value, as on the GPU (tiles and inactive voxels keep the flood fill's sign).
double sparse_trilinear(FieldAccessor& accessor, const Eigen::Vector3i& index_offset,
                        const Eigen::Vector3d& x);

struct FieldSample {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit gradient; zero where undefined (off the band)
  double value = 0.0;                                // signed distance [world units]
};

class HostField {
 public:
  // `grid`: a NanoVDB float level set (sdf::to_nanovdb) whose index space is `spec`'s, values in world
  // units, background band_voxels * voxel_size. Nothing is uploaded.
  HostField(NanoGrid grid, const GridSpec& spec, double band_voxels);

  const GridSpec& spec() const { return spec_; }
  double band() const { return band_; }             // half-width [voxels]
  float background() const { return background_; }  // +-this off the band [world units]
  std::size_t band_voxels() const { return band_voxels_; }
  std::size_t host_bytes() const { return host_.size(); }
  const NanoGrid& host() const { return host_; }

  FieldAccessor accessor() const { return grid_->getAccessor(); }

  // field_sample of shaders/common/sparse_field.glsl at `p` [m] relative to the spec's voxel (0,0,0)
  // centre: the trilinear value and the unit central-difference gradient. Its seven trilinear reads
  // (at x and at x +- half a voxel along each axis) take their corners from one block of 3x3x3 voxels
  // read once, the same values the GPU reads one by one.
  FieldSample sample(FieldAccessor& accessor, const Eigen::Vector3d& p) const;

 private:
  GridSpec spec_;
  double band_ = 0.0;
  float background_ = 0.0f;
  std::size_t band_voxels_ = 0;
  NanoGrid host_;
  const nanovdb::FloatGrid* grid_ = nullptr;
};

}  // namespace ts::sdf
