#include "preview/sim_frames.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/log.h"
#include "preview/colors.h"
#include "preview/image.h"
#include "preview/path_calibration.h"
#include "scene/fragments.h"

namespace ts::preview {
namespace {

// Where each kind of body lies in the world: rough walls first, then the props in scene order, then
// the grains (emitters only append them; grains are the dynamic bodies that are not props).
struct BodyRanges {
  std::size_t first_prop = 0, first_grain = 0;
};

BodyRanges body_ranges(const sim::World& world, std::size_t props, std::size_t dynamic_props) {
  const auto dynamic = static_cast<std::size_t>(
      std::count(world.bodies.motion.begin(), world.bodies.motion.end(), sim::MotionType::Dynamic));
  const std::size_t grains = dynamic >= dynamic_props ? dynamic - dynamic_props : 0;
  BodyRanges r;
  r.first_grain = world.bodies.size() - std::min(grains, world.bodies.size());
  r.first_prop = r.first_grain - std::min(props, r.first_grain);
  return r;
}

// The box `from` moves to towards `to`: at once where `to` is wider, by `rate` of the gap where narrower.
Aabb widen_at_once_narrow_slowly(const Aabb& from, const Aabb& to, double rate) {
  Aabb out = from;
  for (int k = 0; k < 3; ++k) {
    out.min[k] = to.min[k] < from.min[k] ? to.min[k] : from.min[k] + rate * (to.min[k] - from.min[k]);
    out.max[k] = to.max[k] > from.max[k] ? to.max[k] : from.max[k] + rate * (to.max[k] - from.max[k]);
  }
  return out;
}

}  // namespace

FrameSettings frame_settings(const scene::OutputSettings& output) {
  FrameSettings s;
  s.camera = output.camera;
  s.color_by = output.color_by;
  s.walls = output.walls;
  return s;
}

SimFrameWriter::SimFrameWriter(gpu::Context& context, const scene::Scene& scene)
    : SimFrameWriter(context, scene, frame_settings(scene.output)) {}

SimFrameWriter::SimFrameWriter(gpu::Context& context, const scene::Scene& scene, const FrameSettings& settings)
    : renderer_(context),
      settings_(settings),
      walls_(scene),
      gravity_(scene.gravity.norm()) {
  // The shadow map and G-buffer by whichever path a calibration found faster on this device.
  const GpuPathChoice path = choose_gpu_path(context, GpuPath::Auto);
  renderer_.set_gpu_path(path.path);
  log::info("frames: gpu path {}", path.describe());
  try {
    renderer_.check_image_size(settings_.camera.width, settings_.camera.height);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", scene::scene_location(scene, "output.camera.size"), e.what()));
  }
  for (const auto& p : scene.props) {
    const std::size_t bodies = scene::prop_body_count(p);
    prop_ranges_.push_back({static_cast<std::uint32_t>(props_), static_cast<std::uint32_t>(bodies), p.breakable});
    props_ += bodies;
    dynamic_props_ += p.motion == sim::MotionType::Dynamic ? bodies : 0;
  }
  for (const auto& e : scene.emitters) {
    if (e.type != scene::EmitterType::Pour) continue;  // fill and column grains are there from the start
    emitter_box_.extend(e.min);
    emitter_box_.extend(e.max);
  }
}

Particles SimFrameWriter::particles_of(const sim::World& world) {
  const Eigen::Vector3f sand(0.86f, 0.68f, 0.42f), wall(0.62f, 0.63f, 0.66f), prop(0.45f, 0.58f, 0.75f);
  const BodyRanges ranges = body_ranges(world, props_, dynamic_props_);
  Particles out;
  out.centers = sim::particle_positions(world);
  const std::size_t n = world.particles.size();
  out.radii.resize(n);
  out.colors.resize(n);
  // The field's range: heights over the grains (all particles when there is none), speeds from 0 to
  // the free-fall speed over the first frame's height.
  double z_min = std::numeric_limits<double>::max(), z_max = std::numeric_limits<double>::lowest();
  std::vector<double> speed(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = world.particles.body[i];
    if (b >= ranges.first_grain || ranges.first_grain == world.bodies.size()) {
      z_min = std::min(z_min, out.centers[i].z());
      z_max = std::max(z_max, out.centers[i].z());
    }
    const Eigen::Vector3d arm = world.bodies.orientation[b] * world.particles.offset[i];
    speed[i] = (world.bodies.linear_velocity[b] + world.bodies.angular_velocity[b].cross(arm)).norm();
  }
  if (speed_scale_ == 0) {
    const double from_height = std::sqrt(2.0 * gravity_ * std::max(z_max - z_min, 0.0));
    speed_scale_ =
        from_height > 1e-6 ? from_height : std::max(*std::max_element(speed.begin(), speed.end()), 1.0);
  }
  // A breakable prop's spheres take their fragment's colour (its lowest particle's body) under "body".
  std::vector<std::uint32_t> fragment;
  const bool fragments = settings_.color_by == scene::FrameColoring::Body && !world.bonds.a.empty();
  if (fragments) {
    std::vector<scene::BodyRange> ranges_now = prop_ranges_;
    for (scene::BodyRange& r : ranges_now) r.first += static_cast<std::uint32_t>(ranges.first_prop);
    fragment = scene::find_fragments(world, ranges_now).label;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = world.particles.body[i];
    out.radii[i] = static_cast<float>(world.particles.radius[i]);
    Eigen::Vector3f c;
    if (b < ranges.first_prop) {
      c = wall;
    } else {
      switch (settings_.color_by) {
        case scene::FrameColoring::Sand:
          c = b >= ranges.first_grain ? vary(sand, b, 0.12f) : prop;
          break;
        case scene::FrameColoring::Height:
          c = viridis((out.centers[i].z() - z_min) / std::max(z_max - z_min, 1e-12));
          break;
        case scene::FrameColoring::Speed:
          c = viridis(speed[i] / speed_scale_);
          break;
        case scene::FrameColoring::Body:
          c = categorical(fragments && fragment[i] != scene::Fragments::kNone ? world.particles.body[fragment[i]] : b);
          break;
      }
    }
    out.colors[i] = pack_rgba8(c);
  }
  return out;
}

Camera SimFrameWriter::follow(const sim::World& world) {
  const BodyRanges ranges = body_ranges(world, props_, dynamic_props_);
  const std::size_t body = ranges.first_prop + prop_ranges_[static_cast<std::size_t>(settings_.camera.follow_prop)].first;
  const Eigen::Vector3d centre = world.bodies.position[body];
  if (settings_.camera.eye) {
    if (!follow_offset_) follow_offset_ = *settings_.camera.eye - centre;
    return Camera{centre + *follow_offset_, centre, settings_.camera.up, settings_.camera.fov};
  }
  const double reach = 2.5 * world.bodies.bounding_radius[body];
  Aabb box;
  box.extend(centre - Eigen::Vector3d::Constant(reach));
  box.extend(centre + Eigen::Vector3d::Constant(reach));
  return frame_box(box, view_direction(settings_.azimuth, settings_.elevation, settings_.camera.up),
                   settings_.camera.up, static_cast<double>(settings_.camera.width) / settings_.camera.height,
                   false, settings_.camera.fov);
}

Camera SimFrameWriter::camera_for(const sim::World& world, const Aabb& grains) {
  if (settings_.camera.follow_prop >= 0) return follow(world);
  if (settings_.camera.eye && settings_.camera.target)
    return Camera{*settings_.camera.eye, *settings_.camera.target, settings_.camera.up, settings_.camera.fov};
  Aabb wanted = grains;
  const Aabb walls = walls_.framing_box(grains);
  for (const Aabb& b : {walls, emitter_box_}) {
    if (!b.valid()) continue;
    wanted.extend(b.min);
    wanted.extend(b.max);
  }
  framed_ = framed_ ? widen_at_once_narrow_slowly(*framed_, wanted, settings_.narrowing) : wanted;
  return frame_box_tightly(
      *framed_, view_direction(settings_.azimuth, settings_.elevation, settings_.camera.up),
      settings_.camera.up, static_cast<double>(settings_.camera.width) / settings_.camera.height,
      settings_.camera.fov, settings_.margin);
}

Aabb SimFrameWriter::grain_box(const sim::World& world, const Particles& particles) const {
  const BodyRanges ranges = body_ranges(world, props_, dynamic_props_);
  Aabb box;
  for (std::size_t i = 0; i < particles.centers.size(); ++i) {
    if (world.particles.body[i] < ranges.first_grain) continue;
    box.extend(particles.centers[i] - Eigen::Vector3d::Constant(particles.radii[i]));
    box.extend(particles.centers[i] + Eigen::Vector3d::Constant(particles.radii[i]));
  }
  return box.valid() ? box : renderer_.content_box();  // no grain yet: what there is
}

void SimFrameWriter::write(const sim::World& world, std::int64_t frame, const std::filesystem::path& dir) {
  if (world.particles.size() == 0) return;  // nothing emitted yet
  const Particles particles = particles_of(world);
  renderer_.set_particles(particles);
  const Aabb drawn = renderer_.content_box(), grains = grain_box(world, particles);
  if (!ground_level_) ground_level_ = std::min(drawn.min.z(), walls_.floor_level().value_or(drawn.min.z()));
  camera_ = camera_for(world, grains);
  RenderSettings s;
  s.width = settings_.camera.width;
  s.height = settings_.camera.height;
  s.camera = camera_;
  s.up = Eigen::Vector3d::UnitZ();  // the ground's normal: the scene's up, whatever the image's
  s.ground_level = ground_level_;
  s.keep_buffers = settings_.walls && !walls_.empty();
  RenderResult result = renderer_.render(s);
  if (settings_.walls) draw_walls(result.image, result.layers, camera_, walls_, grains, ground_level_);
  write_png(dir / fmt::format("frame_{:06d}.png", frame), result.image);
}

}  // namespace ts::preview
