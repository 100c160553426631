#include "preview/sim_frames.h"

#include <fmt/format.h>

#include <algorithm>

#include "preview/colors.h"
#include "preview/image.h"

namespace ts::preview {

SimFrameWriter::SimFrameWriter(gpu::Context& context, const sim::Scene& scene, const FrameSettings& settings)
    : renderer_(context), settings_(settings) {
  for (const auto& e : scene.emitters) {
    if (e.type == sim::EmitterType::Column) {
      emitter_box_.extend(e.centre - Eigen::Vector3d(e.radius, e.radius, 0.0));
      emitter_box_.extend(e.centre + Eigen::Vector3d(e.radius, e.radius, 0.0));
    } else {
      emitter_box_.extend(e.min);
      emitter_box_.extend(e.max);
    }
  }
}

Particles SimFrameWriter::particles_of(const sim::World& world) {
  const Eigen::Vector3f sand(0.86f, 0.68f, 0.42f), wall(0.62f, 0.63f, 0.66f), prop(0.45f, 0.58f, 0.75f);
  Particles out;
  out.centers = sim::particle_positions(world);
  const std::size_t n = world.particles.size();
  out.radii.resize(n);
  out.colors.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = world.particles.body[i];
    const bool is_static = world.bodies.motion[b] == sim::MotionType::Static;
    const bool grain = world.bodies.particle_count[b] == 4 && world.bodies.motion[b] == sim::MotionType::Dynamic;
    out.radii[i] = static_cast<float>(world.particles.radius[i]);
    out.colors[i] = pack_rgba8(is_static ? wall : grain ? vary(sand, b, 0.12f) : prop);
  }
  return out;
}

void SimFrameWriter::write(const sim::World& world, std::int64_t frame, const std::filesystem::path& dir) {
  const Particles particles = particles_of(world);
  if (particles.centers.empty()) return;  // nothing emitted yet
  renderer_.set_particles(particles);
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  if (!camera_) {
    Aabb box = renderer_.content_box();
    ground_level_ = box.min.z();
    if (emitter_box_.valid()) {
      box.extend(emitter_box_.min);
      box.extend(emitter_box_.max);
    }
    for (const auto& plane : world.walls.planes) {
      box.extend(plane.point);
      if (plane.normal.z() > 0.9) ground_level_ = std::min(ground_level_, plane.point.z());
    }
    camera_ = frame_box(box, view_direction(settings_.view, up), view_image_up(settings_.view, up),
                        static_cast<double>(settings_.width) / settings_.height, false, 30.0);
  }
  RenderSettings s;
  s.width = settings_.width;
  s.height = settings_.height;
  s.camera = *camera_;
  s.up = up;
  s.ground_level = ground_level_;
  write_png(dir / fmt::format("frame_{:06d}.png", frame), renderer_.render(s).image);
}

}  // namespace ts::preview
