#include "sdf/sdf_texture.h"

#include <string>
#include <utility>

#include "core/error.h"

namespace ts::sdf {

SdfTexture::SdfTexture(const GridSpec& spec, int max_3d_texture_size) : spec_(spec) {
  if (spec.dims.maxCoeff() > max_3d_texture_size) {
    throw GpuError("an SDF texture of " + std::to_string(spec.dims.maxCoeff()) +
                   " voxels per side exceeds this GPU's 3D texture limit (" + std::to_string(max_3d_texture_size) +
                   "); use a larger voxel size");
  }
  if (spec.voxel_count() >= (std::size_t{1} << 32)) {
    throw GpuError("an SDF texture of " + std::to_string(spec.voxel_count()) + " voxels exceeds 2^32 voxels");
  }
  glCreateTextures(GL_TEXTURE_3D, 1, &id_);
  glTextureStorage3D(id_, 1, GL_RGBA32F, spec.dims.x(), spec.dims.y(), spec.dims.z());
  if (glGetError() == GL_OUT_OF_MEMORY) {
    glDeleteTextures(1, &id_);
    id_ = 0;
    throw GpuError("out of GPU memory for the " + std::to_string(spec.voxel_count() * 16 >> 20) + " MiB SDF texture");
  }
  glTextureParameteri(id_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(id_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum axis : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTextureParameteri(id_, axis, GL_CLAMP_TO_EDGE);
}

SdfTexture::~SdfTexture() {
  if (id_) glDeleteTextures(1, &id_);
}

SdfTexture::SdfTexture(SdfTexture&& other) noexcept : spec_(other.spec_), id_(std::exchange(other.id_, 0)) {}

SdfTexture& SdfTexture::operator=(SdfTexture&& other) noexcept {
  if (this != &other) {
    if (id_) glDeleteTextures(1, &id_);
    spec_ = other.spec_;
    id_ = std::exchange(other.id_, 0);
  }
  return *this;
}

}  // namespace ts::sdf
