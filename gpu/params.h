#pragma once
// Typed kernel parameters: the C++ view of shaders/common/params.h, pinned here so a struct change
// that breaks std140 agreement fails the build (tests/gpu/params_test.cpp checks the same numbers
// against what the GLSL compiler reports), and the uniform buffers that carry them to a kernel.
#include <cstddef>
#include <cstring>
#include <span>
#include <vector>

#include "gpu/gl.h"
#include "shaders/common/params.h"

namespace ts::gpu {

// One kernel's parameters in a GL uniform buffer of its own (reused for every dispatch). `values`
// persists between binds, so a caller sets only what changed.
template <typename T>
class ParamBlock {
 public:
  T values{};

  // Uploads `values` when they differ from the last upload (one glNamedBufferSubData: no GPU sync;
  // a draw or dispatch already issued keeps reading what it was issued with) and binds the buffer at
  // uniform-block `slot`. Call it right before the dispatch or draw that reads it: slots are per pass.
  void bind(GLuint slot) {
    if (!buffer_.id()) buffer_ = Buffer(sizeof(T));
    if (!uploaded_ || std::memcmp(&last_, &values, sizeof(T)) != 0) {
      buffer_.upload(&values, sizeof(T));
      last_ = values;
      uploaded_ = true;
    }
    buffer_.bind(slot, GL_UNIFORM_BUFFER);
  }

 private:
  Buffer buffer_;
  T last_{};
  bool uploaded_ = false;
};

// Parameters of a run of draws, all uploaded at once and bound one at a time (glBindBufferRange):
// rewriting one buffer between draws would make a software renderer (llvmpipe) finish the draws
// queued on it first.
template <typename T>
class ParamArray {
 public:
  // Uploads `entries`, each at a multiple of GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT.
  void upload(std::span<const T> entries) {
    if (!stride_) {
      GLint alignment = 0;
      glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &alignment);
      const std::size_t a = static_cast<std::size_t>(std::max(alignment, 1));
      stride_ = (sizeof(T) + a - 1) / a * a;
    }
    std::vector<unsigned char> bytes(entries.size() * stride_);
    for (std::size_t i = 0; i < entries.size(); ++i) std::memcpy(&bytes[i * stride_], &entries[i], sizeof(T));
    if (buffer_.bytes() < bytes.size()) buffer_ = Buffer(bytes.size());
    buffer_.upload(bytes.data(), bytes.size());
  }
  // Binds entry `index` of the last upload at uniform-block `slot`.
  void bind(std::size_t index, GLuint slot) const {
    glBindBufferRange(GL_UNIFORM_BUFFER, slot, buffer_.id(), static_cast<GLintptr>(index * stride_),
                      static_cast<GLsizeiptr>(sizeof(T)));
  }

 private:
  Buffer buffer_;
  std::size_t stride_ = 0;
};

namespace params {

static_assert(sizeof(mat4) == 64 && alignof(mat4) == 16);
static_assert(sizeof(ItemCount) == 16);
static_assert(sizeof(GridParams) == 32);
static_assert(offsetof(GridParams, cell) == 16);
static_assert(sizeof(FieldParams) == 64);
static_assert(offsetof(FieldParams, scale) == 16 && offsetof(FieldParams, root_first) == 32);
static_assert(offsetof(FieldParams, roots) == 48);
static_assert(sizeof(RelaxParams) == 48);
static_assert(offsetof(RelaxParams, kernel) == 16 && offsetof(RelaxParams, limits) == 32);
static_assert(sizeof(CertifyParams) == 64);
static_assert(offsetof(CertifyParams, search) == 16 && offsetof(CertifyParams, lengths) == 32);
static_assert(offsetof(CertifyParams, refine) == 48);
static_assert(sizeof(ScanConvertParams) == 32);
static_assert(offsetof(ScanConvertParams, grid) == 16);
static_assert(sizeof(BandParams) == 48);
static_assert(offsetof(BandParams, voxels) == 16 && offsetof(BandParams, band) == 32);
static_assert(sizeof(LeafBuildParams) == 64);
static_assert(offsetof(LeafBuildParams, leaves) == 16 && offsetof(LeafBuildParams, cells) == 32);
static_assert(offsetof(LeafBuildParams, band) == 48);
static_assert(sizeof(BrickPairParams) == 64);
static_assert(offsetof(BrickPairParams, bricks) == 16 && offsetof(BrickPairParams, counts) == 32);
static_assert(offsetof(BrickPairParams, reach) == 48);
static_assert(sizeof(ComputeScanParams) == 64);
static_assert(offsetof(ComputeScanParams, slab) == 16 && offsetof(ComputeScanParams, pairs) == 32);
static_assert(offsetof(ComputeScanParams, band) == 48);
static_assert(sizeof(SimContactParams) == 80);
static_assert(offsetof(SimContactParams, limits) == 32 && offsetof(SimContactParams, step) == 48);
static_assert(offsetof(SimContactParams, lists) == 64);
static_assert(sizeof(SimContactParams64) == 96);
static_assert(offsetof(SimContactParams64, limits) == 32 && offsetof(SimContactParams64, step) == 64);
static_assert(offsetof(SimContactParams64, lists) == 48);
static_assert(sizeof(SimBondParams) == 32 && offsetof(SimBondParams, step) == 16);
static_assert(sizeof(SimBondParams64) == 64 && offsetof(SimBondParams64, step) == 32);
static_assert(sizeof(SimListParams) == 32 && offsetof(SimListParams, lengths) == 16);
static_assert(sizeof(SimIntegrateParams) == 80);
static_assert(offsetof(SimIntegrateParams, gravity_dt) == 48 && offsetof(SimIntegrateParams, time) == 64);
static_assert(sizeof(SimIntegrateParams64) == 128);
static_assert(offsetof(SimIntegrateParams64, gravity_dt) == 64 && offsetof(SimIntegrateParams64, time) == 96);
static_assert(sizeof(SimMetricsParams) == 32);
static_assert(sizeof(SimFixupParams) == 32);
static_assert(sizeof(SimGatherParams) == 16);
static_assert(sizeof(CameraParams) == 224);
static_assert(offsetof(CameraParams, eye) == 128 && offsetof(CameraParams, lens) == 192);
static_assert(offsetof(CameraParams, viewport) == 208);
static_assert(sizeof(VolumeParams) == 32);
static_assert(sizeof(ParticleParams) == 32);
static_assert(sizeof(RaycastParams) == 48);
static_assert(sizeof(PreviewComputeParams) == 96);
static_assert(offsetof(PreviewComputeParams, steps) == 32 && offsetof(PreviewComputeParams, particle_color) == 64);
static_assert(offsetof(PreviewComputeParams, mode) == 80);
static_assert(sizeof(ShadeParams) == 192);
static_assert(offsetof(ShadeParams, flags) == 64 && offsetof(ShadeParams, background_bottom) == 176);
static_assert(sizeof(SaxpyParams) == 32);
static_assert(sizeof(SolidColorParams) == 16);
static_assert(sizeof(FieldProbeParams) == 32);

}  // namespace params
}  // namespace ts::gpu
