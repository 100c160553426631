#pragma once
// PNG frames of `tetrasand sim` ([output] frames = true): every particle of the world as a sphere
// impostor, lit by one directional light with shadow mapping (thesis 5.2), over a ground plane at
// the lowest floor. The camera frames the scene once, at the first frame (the particles, the
// emitters' regions and the floors' points), and keeps still after, so frames make a film.
#include <filesystem>
#include <optional>

#include "gpu/context.h"
#include "preview/camera.h"
#include "preview/renderer.h"
#include "sim/scene.h"
#include "sim/world.h"

namespace ts::preview {

struct FrameSettings {
  int width = 640, height = 480;  // pixels
  View view = View::Iso;          // relative to +z up (the scene convention)
};

class SimFrameWriter {
 public:
  SimFrameWriter(gpu::Context& context, const sim::Scene& scene, const FrameSettings& settings = {});

  // Writes dir/frame_NNNNNN.png (NNNNNN = frame) atomically.
  void write(const sim::World& world, std::int64_t frame, const std::filesystem::path& dir);

  // The world's particles: grains in sand colours varied grain by grain, static bodies (rough
  // walls) grey, other bodies (props) steel blue.
  static Particles particles_of(const sim::World& world);

 private:
  Renderer renderer_;
  FrameSettings settings_;
  Aabb emitter_box_;           // where emitters put grains [m]
  std::optional<Camera> camera_;
  double ground_level_ = 0.0;  // m along +z, fixed at the first frame
};

}  // namespace ts::preview
