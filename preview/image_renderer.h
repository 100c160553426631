#pragma once
// What the preview draws and returns, whichever renderer draws it: the GL one (preview/renderer.h) or
// the CPU one (preview/cpu_renderer.h), and the interface both implement.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"
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

// One row of a renderer's per-pass times: a GL kernel or draw (GPU timer queries) or a CPU pass (wall
// time), accumulated over the renderer's life.
struct PassTime {
  std::string name;
  std::size_t calls = 0;
  double milliseconds = 0.0;
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
  // Per-pass times so far (when constructed with timings): as rows, and as the --timings table.
  virtual std::vector<PassTime> pass_times() = 0;
  virtual std::string timing_report() = 0;
  // What draws: "llvmpipe (...)", "the CPU (16 TBB threads)".
  virtual std::string device() const = 0;
};

}  // namespace ts::preview
