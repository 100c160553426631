#pragma once
// The off-screen preview renderer (thesis 5.2 and 6.4). Everything draws into framebuffer objects of
// a surfaceless context (gpu::Context); nothing needs a window. Per frame:
//   1. shadow map: particles and the SDF, depth only, from the key light (orthographic);
//   2. G-buffer: particles as sphere impostors (true depth and normal), then the SDF ray-cast over
//      its rasterised bounding box, each ray stopping at the particle already drawn at its pixel;
//   3. optional CPU colouring of the SDF surface by a scalar (error, distance to the particles);
//   4. lighting: diffuse + specular key light with 3x3 PCF shadows, hemisphere ambient, SDF ambient
//      occlusion, a ground plane catching the shadows; read back as 8-bit RGBA.
// Same input, same device, same pixels: no blending order, no atomics, no randomness.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh.h"
#include "gpu/context.h"
#include "preview/compute_passes.h"
#include "preview/image_renderer.h"

namespace ts::preview {

class Renderer final : public ImageRenderer {
 public:
  // Compiles the preview shaders. Requires a current context; GpuError when a pass cannot run.
  explicit Renderer(gpu::Context& context, bool timings = false);
  ~Renderer() override;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Uploads the SDF's sparse NanoVDB grid (sdf::SparseField): memory follows the band, not the box.
  // One storage buffer, or up to 8 when the grid is larger than the device's largest storage block
  // (`field_block_bytes` when not 0: tests cut a small grid into chunks); GpuError naming the size when
  // even 8 cannot hold it.
  void set_volume(SdfVolume volume, std::size_t field_block_bytes = 0);
  void load_volume(SdfVolume volume) override { set_volume(std::move(volume)); }
  void set_particles(const Particles& particles) override;
  // The storage blocks the SDF occupies on the GPU: 1, up to 8 when chunked, 0 before set_volume.
  int field_chunks() const;

  // The box of what is drawn: the SDF's surface (voxels at or inside the zero level) and the
  // particle spheres. Invalid when nothing is loaded.
  Aabb content_box() const override;
  // The largest image the device renders (GL_MAX_VIEWPORT_DIMS, GL_MAX_TEXTURE_SIZE, framebuffer).
  Eigen::Vector2i max_image_size() const;

  // ts::InputError for a side below 1 pixel or above max_image_size().
  void check_image_size(int width, int height) const override;

  // ts::InputError for a bad image size (check_image_size), a bad camera, or nothing to draw.
  RenderResult render(const RenderSettings& settings) override;

  // How the shadow map and G-buffer are made: draws or compute kernels (preview/compute_passes.h);
  // Raster or Compute (std::invalid_argument for Auto, which the caller resolves by
  // preview::choose_gpu_path, preview/path_calibration.h: calibrated per device, cached). The raster
  // path until set.
  void set_gpu_path(GpuPath path);
  GpuPath gpu_path() const;  // Raster or Compute

  // Per-pass GPU times so far (when constructed with timings).
  std::vector<PassTime> pass_times() override;
  std::string timing_report() override;
  std::string device() const override;  // the context's summary

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ts::preview
