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
#include "preview/camera.h"
#include "preview/image.h"
#include "preview/volume.h"

namespace ts::preview {

// Spheres to draw: sampled particles, simulation grains.
struct Particles {
  std::vector<Eigen::Vector3d> centers;  // m, world
  std::vector<float> radii;              // m: one per particle, or a single radius for all
  std::vector<std::uint32_t> colors;     // sRGB RGBA8 per particle (red in the low byte); empty: one colour
};

// Colours the ray-cast surface by a scalar evaluated on the CPU at each visible surface pixel's
// world position, mapped through the colour map from 0 to max_value (preview/colors.h).
struct SurfaceScalar {
  std::function<double(const Eigen::Vector3d& world)> value;  // thread-safe: called in parallel
  double max_value = 1.0;
};

struct RenderSettings {
  int width = 512, height = 512;           // pixels
  Camera camera;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // world up (+z, the tool's convention): the ground plane's
                                                  // normal, the light's frame
  std::optional<Eigen::Vector3d> light;    // towards the key light, world; default: upper left, behind the camera
  bool shadows = true;
  bool ground = true;                      // a ground plane at the lowest point of the scene
  std::optional<double> ground_level;      // m along `up`; default: the scene's lowest point
  bool alpha = false;                      // transparent background (the ground shows only its shadows)
  Eigen::Vector3f surface_color{0.66f, 0.70f, 0.76f};   // sRGB
  Eigen::Vector3f particle_color{0.93f, 0.56f, 0.20f};  // sRGB
  SurfaceScalar surface_scalar;            // empty `value`: surface_color
  int shadow_map_size = 0;                 // texels per side; 0: from the image size
  bool keep_buffers = false;               // also return the per-pixel layer and normal (tests)
};

enum class Layer : std::uint8_t { Background = 0, Surface = 1, Particle = 2 };

struct ScalarSummary {
  std::size_t pixels = 0;  // surface pixels coloured
  double mean = 0.0, max = 0.0;
};

struct RenderResult {
  Image image;                          // RGBA8, top row first
  std::vector<Layer> layers;            // keep_buffers: per pixel, top row first
  std::vector<Eigen::Vector3f> normals; // keep_buffers: unit world normal per pixel (0 on background)
  ScalarSummary scalar;                 // of surface_scalar, over the visible surface
  double seconds = 0.0;                 // wall time of render()
};

// What a preview renderer does, on the GL device (Renderer) or on the CPU (CpuRenderer,
// preview/cpu_renderer.h): the commands load the scene and draw views through this, whichever runs.
class ImageRenderer {
 public:
  virtual ~ImageRenderer() = default;
  // The SDF to ray-cast; ts::InputError for an empty one or one under 2 voxels a side.
  virtual void load_volume(SdfVolume volume) = 0;
  // ts::InputError for a radius count other than 1 or n, a colour count other than 0 or n, or a
  // particle with a non-finite centre or a radius that is not positive.
  virtual void set_particles(const Particles& particles) = 0;
  // The box of what is drawn: the SDF's surface and the particle spheres; invalid when empty.
  virtual Aabb content_box() const = 0;
  // ts::InputError for a side below 1 pixel or above what the renderer can draw.
  virtual void check_image_size(int width, int height) const = 0;
  // ts::InputError for a bad image size, a bad camera, or nothing to draw.
  virtual RenderResult render(const RenderSettings& settings) = 0;
  // Per-pass times so far (when constructed with timings).
  virtual std::string timing_report() = 0;
  // What draws: "llvmpipe (...)", "the CPU (16 TBB threads)".
  virtual std::string device() const = 0;
};

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

  // Per-pass GPU times so far (when constructed with timings).
  std::string timing_report() override;
  std::string device() const override;  // the context's summary

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The key light's default direction: from the upper left, behind the camera, about 50 degrees above
// the ground plane, turning with the camera about `up`.
Eigen::Vector3d default_light(const Camera& camera, const Eigen::Vector3d& up);

}  // namespace ts::preview
