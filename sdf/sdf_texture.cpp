#include "sdf/sdf_texture.h"

#include <string>

#include "core/error.h"

namespace ts::sdf {

SdfTexture::SdfTexture(const GridSpec& spec, int max_3d_texture_size) : spec_(spec) {
  if (spec.dims.maxCoeff() > max_3d_texture_size) {
    throw GpuError("an SDF texture of " + std::to_string(spec.dims.maxCoeff()) +
                   " voxels per side exceeds this GPU's 3D texture limit (" +
                   std::to_string(max_3d_texture_size) + "); use a larger voxel size");
  }
  if (spec.voxel_count() >= (std::size_t{1} << 32)) {
    throw GpuError("an SDF texture of " + std::to_string(spec.voxel_count()) + " voxels exceeds 2^32 voxels");
  }
  texture_ = gpu::Texture::create_3d(GL_RGBA32F, spec.dims.x(), spec.dims.y(), spec.dims.z(), "SDF texture");
  texture_.set_sampling(GL_LINEAR);
}

}  // namespace ts::sdf
