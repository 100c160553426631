#pragma once
// PNG frames of `tetrasand sim` ([output] frames = true): every particle of the world as a sphere
// impostor, lit by one directional light with shadow mapping (thesis 5.2), over a ground plane at
// the lowest floor, with the scene's walls drawn faintly over them (preview/frame_walls.h).
// The camera ([output.camera], scene/scene.h) is one of:
//   fixed       eye and target given: the camera never moves;
//   follow prop the prop's centre of mass stays at the image centre (eye, if given, keeps its offset
//               from it; else the prop and 2.5 times its bounding radius around it are framed);
//   default     a three-quarter view (FrameSettings::azimuth, elevation) of the grains and the walls
//               around them (FrameWalls::framing_box) and the pour emitters' regions, framed again at
//               every frame by the tightest perspective fit of that box (camera.h's frame_box_tightly):
//               the framing box widens at once when the grains spread and narrows by `narrowing` of the
//               gap per frame when they gather, so a film neither loses grains nor jitters. Props are
//               not framed: they show where they meet the grains (a tall prop may leave the top of the
//               picture), and follow = "prop NAME" keeps one in view.
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <vector>

#include "gpu/context.h"
#include "preview/camera.h"
#include "preview/frame_walls.h"
#include "preview/renderer.h"
#include "scene/scene.h"
#include "scene/scene_world.h"
#include "sim/world.h"

namespace ts::preview {

struct FrameSettings {
  scene::FrameCamera camera;  // [output.camera]: size, eye/target, up, fov, the followed prop
  // The default camera's direction relative to camera.up (camera.h's view_direction): degrees from the
  // front axis towards the side axis, and above the horizon. A three-quarter view rather than the iso
  // view (45, 35.26): a box's footprint fills more of a 4:3 image seen closer to its front, and a
  // prop resting in a bed hides less of it from lower down (prop_drop's settled frames: grains on
  // 24-26 % of the pixels here, 21-25 % from the iso view, docs/first-use.md).
  double azimuth = 30.0, elevation = 30.0;
  double margin = 1.08;  // the framed box spans 1 / margin of the image in its tighter direction
  scene::FrameColoring color_by = scene::FrameColoring::Sand;
  bool walls = true;  // draw the boundaries (preview/frame_walls.h)
  // Share of the gap the default framing closes per frame when content shrinks: a quarter, so a bed
  // that settles out of a tall fill is framed closely within about ten frames (0.75^10 = 6 %).
  double narrowing = 0.25;
};

// The frame settings a scene's [output] and [output.camera] ask for.
FrameSettings frame_settings(const scene::OutputSettings& output);

class SimFrameWriter {
 public:
  // With the scene's own settings (frame_settings(scene.output)), or with `settings`.
  SimFrameWriter(gpu::Context& context, const scene::Scene& scene);
  SimFrameWriter(gpu::Context& context, const scene::Scene& scene, const FrameSettings& settings);

  // Writes dir/frame_NNNNNN.png (NNNNNN = frame) atomically; nothing while the world has no particle.
  void write(const sim::World& world, std::int64_t frame, const std::filesystem::path& dir);

  // The world's particles coloured by settings.color_by: grains and props by the field (sand: grains
  // in sand colours varied grain by grain, props steel blue; body: a colour per body, and per fragment
  // for a breakable prop's spheres), static bodies (rough walls) grey.
  Particles particles_of(const sim::World& world);

  // The camera of the last frame written, and the box the default camera framed (tests).
  const Camera& camera() const { return camera_; }
  const std::optional<Aabb>& framed_box() const { return framed_; }

 private:
  Camera camera_for(const sim::World& world, const Aabb& grains);
  // The box of the grains' spheres (m); all particles' before there is any grain.
  Aabb grain_box(const sim::World& world, const Particles& particles) const;
  Camera follow(const sim::World& world);

  Renderer renderer_;
  FrameSettings settings_;
  FrameWalls walls_;
  Aabb emitter_box_;       // m: where pour emitters release grains
  std::size_t props_ = 0;  // bodies of the scene's [[prop]]s (a breakable prop: one per sphere)
  std::size_t dynamic_props_ = 0;  // of them, dynamic
  // Each prop's bodies, `first` counted from the first prop body (scene/scene_world.h BodyRange).
  std::vector<scene::BodyRange> prop_ranges_;
  double gravity_ = 0;                            // m/s^2, |g|
  std::optional<double> ground_level_;            // m along +z, fixed at the first frame
  std::optional<Aabb> framed_;                    // the default camera's smoothed framing box
  std::optional<Eigen::Vector3d> follow_offset_;  // m, eye - prop centre (follow with an eye)
  double speed_scale_ = 0;  // m/s, the top of the speed colour map (fixed at the first frame)
  Camera camera_;
};

}  // namespace ts::preview
