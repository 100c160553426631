#pragma once
// The SDF left in GPU memory for the stages that run in the same process (the sampler): a dense
// RGBA32F 3D texture, per voxel xyz = unit gradient, w = signed distance [world units], with
// hardware trilinear filtering and clamp-to-edge. The same values DenseSdf holds on the host; voxels
// outside the band hold +-band (world units) with the flood fill's sign and a zero gradient.
#include <cstddef>

#include "gpu/gl.h"
#include "sdf/grid.h"

namespace ts::sdf {

// Owns one GL texture. Move-only; empty (id() == 0) when default-constructed or moved from.
class SdfTexture {
 public:
  SdfTexture() = default;
  // Allocates an uninitialised dims.x * dims.y * dims.z RGBA32F texture. Throws GpuError when a side
  // exceeds the GPU's 3D texture limit or the GPU is out of memory. Needs a current context.
  SdfTexture(const GridSpec& spec, int max_3d_texture_size);
  ~SdfTexture();
  SdfTexture(SdfTexture&& other) noexcept;
  SdfTexture& operator=(SdfTexture&& other) noexcept;
  SdfTexture(const SdfTexture&) = delete;
  SdfTexture& operator=(const SdfTexture&) = delete;

  GLuint id() const { return id_; }
  bool empty() const { return id_ == 0; }
  const GridSpec& spec() const { return spec_; }
  std::size_t bytes() const { return id_ ? spec_.voxel_count() * 16 : 0; }

 private:
  GridSpec spec_;
  GLuint id_ = 0;
};

}  // namespace ts::sdf
