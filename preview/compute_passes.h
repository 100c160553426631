#pragma once
// The preview's shadow map and G-buffer made by compute kernels instead of draws (issue 45): on
// NVIDIA's GH100 (H100/H200) only 4 of 132 SMs run graphics shaders while compute uses all of them
// (docs/benchmarks/preview.md). Per image, each a dispatch:
//   1. splat.comp, depths: per sphere its screen box, per pixel the exact ray-sphere hit, the nearest
//      depth by an atomic vote (shaders/preview/splat.glsl states the scheme);
//   2. splat.comp, ids: the sphere whose depth won, the smallest id among equal depths;
//   3. trace.comp: a work group per 8 x 8 tile ray-casts the sparse SDF with the fragment ray cast's
//      own march (shaders/preview/march.glsl) up to the sphere, and writes the G-buffer's albedo and
//      normal/layer images and the pixel's depth;
//   4. the depth is copied into the depth texture on the GPU (a pixel-unpack upload from the buffer).
// The shadow map is the same passes from the light, depth only. The lighting pass is the renderer's.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gpu/gl.h"
#include "gpu/graphics.h"
#include "gpu/params.h"

namespace ts::gpu {
class Context;
}

namespace ts::preview {

// How the GPU renderer makes its shadow map and G-buffer: draws (raster) or compute kernels.
enum class GpuPath { Auto, Raster, Compute };

// "auto", "raster", "compute": the --gpu-path spellings.
const char* gpu_path_name(GpuPath path);
// The inverse of gpu_path_name; nullopt for any other text.
std::optional<GpuPath> parse_gpu_path(std::string_view text);
// What a compute image draws; the caller has bound the camera, the spheres and colours, and (with
// has_volume) the sparse field and its VolumeParams at the preview's slots (shaders/preview/bindings.h).
struct ComputeScene {
  std::size_t particle_count = 0;
  bool per_particle_color = false;
  Eigen::Vector3f particle_color = Eigen::Vector3f::Zero();  // sRGB
  Eigen::Vector3f surface_color = Eigen::Vector3f::Zero();   // sRGB
  bool has_volume = false;
};

// Where a compute image goes: a depth texture (GL_DEPTH_COMPONENT32F) of the image's size, and for a
// G-buffer its albedo (GL_RGBA8) and normal/layer (GL_RGBA16F) textures; both null for a shadow map.
struct ComputeTarget {
  gpu::Texture* depth = nullptr;
  gpu::Texture* albedo = nullptr;
  gpu::Texture* normal = nullptr;
};

class ComputePasses {
 public:
  // Compiles the kernels, the ray caster for the field's chunking (sdf::SparseField::shader_defines).
  ComputePasses(const gpu::ShaderLibrary& library, const std::vector<std::string>& volume_defines);
  // Recompiles the ray caster when the field's chunking changes.
  void set_volume_defines(const gpu::ShaderLibrary& library, const std::vector<std::string>& volume_defines);

  // One image of `scene` into `target` (depth only when target.albedo is null). `block` carries the
  // kernels' parameters: a block per image kind, so a frame rewrites none between its dispatches.
  void draw(gpu::Queue& queue, const ComputeScene& scene, const ComputeTarget& target,
            gpu::ParamBlock<gpu::params::PreviewComputeParams>& block);

 private:
  void ensure_pixels(std::size_t pixels);

  std::vector<std::string> volume_defines_;
  gpu::Program splat_, trace_;
  gpu::Buffer depth_bits_, particle_ids_;  // per pixel, shaders/preview/bindings.h
  std::size_t pixels_ = 0;
};

}  // namespace ts::preview
