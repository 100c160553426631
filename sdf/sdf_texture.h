#pragma once
// The SDF left in GPU memory for the stages that run in the same process (the sampler): a dense
// RGBA32F 3D texture, per voxel xyz = unit gradient, w = signed distance [world units], with
// hardware trilinear filtering and clamp-to-edge. The same values DenseSdf holds on the host; voxels
// outside the band hold +-band (world units) with the flood fill's sign and a zero gradient.
#include <cstddef>

#include "gpu/graphics.h"
#include "sdf/grid.h"

namespace ts::sdf {

// Owns one GL texture. Move-only; empty (id() == 0) when default-constructed or moved from.
class SdfTexture {
 public:
  SdfTexture() = default;
  // Allocates an uninitialised dims.x * dims.y * dims.z RGBA32F texture. Throws GpuError when a side
  // exceeds the GPU's 3D texture limit or the GPU is out of memory. Needs a current context.
  SdfTexture(const GridSpec& spec, int max_3d_texture_size);

  GLuint id() const { return texture_.id(); }
  bool empty() const { return texture_.empty(); }
  const GridSpec& spec() const { return spec_; }
  std::size_t bytes() const { return texture_.bytes(); }
  const gpu::Texture& texture() const { return texture_; }

 private:
  GridSpec spec_;
  gpu::Texture texture_;
};

}  // namespace ts::sdf
