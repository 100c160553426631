#include "preview/compute_passes.h"

#include <fmt/format.h>

#include "core/error.h"
#include "gpu/context.h"
#include "shaders/preview/bindings.h"

namespace ts::preview {

namespace {

constexpr int kTile = 8;  // pixels along each side of trace.comp's work group

gpu::params::vec4 xyz(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z(), 0.0f}; }

}  // namespace

const char* gpu_path_name(GpuPath path) {
  switch (path) {
    case GpuPath::Auto:
      return "auto";
    case GpuPath::Raster:
      return "raster";
    case GpuPath::Compute:
      return "compute";
  }
  return "auto";
}

std::optional<GpuPath> parse_gpu_path(std::string_view text) {
  for (GpuPath p : {GpuPath::Auto, GpuPath::Raster, GpuPath::Compute}) {
    if (text == gpu_path_name(p)) return p;
  }
  return std::nullopt;
}

ComputePasses::ComputePasses(const gpu::ShaderLibrary& library, const std::vector<std::string>& volume_defines)
    : volume_defines_(volume_defines),
      splat_(gpu::Program::compute(library, "preview/splat.comp")),
      trace_(gpu::Program::compute(library, "preview/trace.comp", volume_defines)) {}

void ComputePasses::set_volume_defines(const gpu::ShaderLibrary& library,
                                       const std::vector<std::string>& volume_defines) {
  if (volume_defines == volume_defines_) return;
  volume_defines_ = volume_defines;
  trace_ = gpu::Program::compute(library, "preview/trace.comp", volume_defines_);
}

void ComputePasses::ensure_pixels(std::size_t pixels) {
  if (pixels <= pixels_) return;
  depth_bits_ = gpu::Buffer(pixels * sizeof(std::uint32_t));
  particle_ids_ = gpu::Buffer(pixels * sizeof(std::uint32_t));
  pixels_ = pixels;
}

void ComputePasses::draw(gpu::Queue& queue, const ComputeScene& scene, const ComputeTarget& target,
                         gpu::ParamBlock<gpu::params::PreviewComputeParams>& block) {
  const int width = target.depth->width(), height = target.depth->height();
  const bool depth_only = target.albedo == nullptr;
  ensure_pixels(static_cast<std::size_t>(width) * height);
  // Zero: no sphere at any pixel, in the complemented encoding of splat.glsl.
  depth_bits_.fill_zero();
  particle_ids_.fill_zero();
  depth_bits_.bind(TS_PREVIEW_DEPTH_BITS);
  particle_ids_.bind(TS_PREVIEW_PARTICLE_IDS);

  const std::uint32_t tiles_x = static_cast<std::uint32_t>((width + kTile - 1) / kTile);
  const std::uint32_t tiles_y = static_cast<std::uint32_t>((height + kTile - 1) / kTile);
  gpu::params::PreviewComputeParams& p = block.values;
  p.flags = {scene.per_particle_color ? 1 : 0, depth_only ? 1 : 0, 512, scene.has_volume ? 1 : 0};
  p.sizes = {static_cast<std::uint32_t>(scene.particle_count), tiles_x, static_cast<std::uint32_t>(width),
             static_cast<std::uint32_t>(height)};
  p.steps = {0.02f, 0.0f, 0.0f, 0.0f};  // as the draw's ray cast (preview/renderer.cpp, draw_volume)
  p.surface_color = xyz(scene.surface_color);
  p.particle_color = xyz(scene.particle_color);
  if (scene.particle_count > 0) {
    for (int pass = 0; pass < 2; ++pass) {  // depths, then the ids of the winning depths
      p.mode = {pass, 0, 0, 0};
      block.bind(TS_PREVIEW_PARAMS);
      queue.dispatch_items(splat_, scene.particle_count);
    }
  } else {
    block.bind(TS_PREVIEW_PARAMS);
  }
  {
    std::optional<gpu::ImageBinding> albedo, normal;
    if (!depth_only) {
      albedo.emplace(TS_PREVIEW_IMAGE_ALBEDO, *target.albedo, GL_WRITE_ONLY);
      normal.emplace(TS_PREVIEW_IMAGE_NORMAL, *target.normal, GL_WRITE_ONLY);
    }
    // The next readers: the depth upload (pixel unpack), the lighting pass (texture fetches) and the
    // read-back of the G-buffer (texture update).
    queue.dispatch_groups(trace_, static_cast<std::size_t>(tiles_x) * tiles_y,
                          GL_PIXEL_BUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                              GL_SHADER_STORAGE_BARRIER_BIT);
  }
  target.depth->upload_from(depth_bits_, GL_DEPTH_COMPONENT, GL_FLOAT);
}

}  // namespace ts::preview
