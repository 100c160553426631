#pragma once
// The preview drawn on the CPU: the same picture as the GL renderer (preview/renderer.h) from the same
// inputs, for machines without a GPU, where the GL renderer runs on Mesa's llvmpipe. Per frame:
//   1. shadow map: a CPU depth map from the key light (orthographic), the particles splatted and the
//      SDF ray-cast into it, sampled with the GL pass's 3x3 percentage-closer filter of bilinear
//      depth comparisons, so the shadows' soft edges match;
//   2. G-buffer: the particles splatted as spheres (each sphere's screen box, the exact ray-sphere hit
//      per pixel, a depth test), then the SDF through OpenVDB's level-set ray intersector
//      (preview/cpu_field.h), each ray stopping at the particle already drawn at its pixel;
//   3. optional colouring of the SDF surface by a scalar;
//   4. lighting: the formulas of shaders/preview/shade.frag with the figures of
//      shaders/preview/look.h.
// Every pass runs on TBB over tiles of pixels; no GL context is needed. Same input, same pixels.
#include <memory>
#include <string>

#include "preview/image_renderer.h"

namespace ts::preview {

class CpuRenderer final : public ImageRenderer {
 public:
  // The largest image side [pixels]: the buffers of an image take about 40 bytes a pixel.
  static constexpr int kMaxImageSide = 16384;

  explicit CpuRenderer(bool timings = false);
  ~CpuRenderer() override;
  CpuRenderer(const CpuRenderer&) = delete;
  CpuRenderer& operator=(const CpuRenderer&) = delete;

  // Reads the volume's OpenVDB level set (SdfVolume::level_set); the NanoVDB copy is not used.
  void load_volume(SdfVolume volume) override;
  void set_particles(const Particles& particles) override;
  Aabb content_box() const override;
  void check_image_size(int width, int height) const override;
  RenderResult render(const RenderSettings& settings) override;
  // Per-pass wall times, in the GL renderer's table layout.
  std::vector<PassTime> pass_times() override;
  std::string timing_report() override;
  std::string device() const override;  // "the CPU (N TBB threads)"

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ts::preview
