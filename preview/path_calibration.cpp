#include "preview/path_calibration.h"

#include <openvdb/tools/LevelSetSphere.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "preview/camera.h"
#include "preview/renderer.h"
#include "preview/volume.h"

namespace ts::preview {
namespace {

// The calibration scene's size: large enough that a hardware GPU's time is the passes', not the
// launches' (512^2 pixels, a field 128 voxels across, 16,384 impostors), and on a software renderer,
// where a 256^2 ray cast of the sparse field takes seconds, small enough to cost about as much as the
// compiling it includes (64^2, 32 voxels, 1,024 impostors).
struct SceneSize {
  int pixels = 512;  // a side, and the shadow map's texels
  int voxels_across = 128;
  int particles = 16384;
};

SceneSize scene_size(const gpu::Context& context) {
  if (context.software()) return {64, 32, 1024};
  return {};
}

constexpr float kSphereRadius = 0.5f;  // m

// The calibration scene's particles: a golden-angle spiral on a shell just outside the sphere, so the
// image holds both the ray-cast surface and the impostors in front of it, as a sample preview does.
Particles spiral_shell(int count) {
  Particles p;
  const double shell = 1.08 * kSphereRadius, golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count, r = std::sqrt(1.0 - z * z), phi = golden * i;
    p.centers.emplace_back(shell * r * std::cos(phi), shell * r * std::sin(phi), shell * z);
  }
  // About touching neighbours: the shell's area over the count is each particle's share.
  p.radii = {static_cast<float>(0.9 * shell * std::sqrt(4.0 / count))};
  return p;
}

}  // namespace

const gpu::CalibrationKind& preview_calibration_kind() {
  static const gpu::CalibrationKind kind{"preview", kPreviewCacheVariable, "compute", "raster"};
  return kind;
}

gpu::PathTiming calibrate_gpu_path(gpu::Context& context) {
  const SceneSize size = scene_size(context);
  const float voxel = 2.0f * kSphereRadius / static_cast<float>(size.voxels_across);
  const auto sphere =
      openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(kSphereRadius, openvdb::Vec3f(0.0f), voxel, 3.0f);
  Renderer renderer(context);
  renderer.set_volume(volume_from_level_set(*sphere, "the built-in calibration sphere"));
  renderer.set_particles(spiral_shell(size.particles));
  RenderSettings s;
  s.width = s.height = s.shadow_map_size = size.pixels;
  s.camera = frame_box(renderer.content_box(), view_direction(View::Iso, s.up), view_image_up(View::Iso, s.up), 1.0,
                       false, 30.0);
  auto seconds = [&](GpuPath path) {
    renderer.set_gpu_path(path);
    return renderer.render(s).seconds;
  };
  // Alternating spreads a load that changes meanwhile over both paths; each path's first run also
  // compiles its programs, so the faster of two runs is the path's own speed.
  gpu::PathTiming timing{1e300, 1e300};
  for (int round = 0; round < 2; ++round) {
    timing.first_seconds = std::min(timing.first_seconds, seconds(GpuPath::Compute));
    timing.second_seconds = std::min(timing.second_seconds, seconds(GpuPath::Raster));
  }
  return timing;
}

GpuPathChoice choose_gpu_path(gpu::Context& context, GpuPath requested,
                              const std::optional<std::filesystem::path>& cache,
                              const std::function<gpu::PathTiming()>& calibrate) {
  if (requested != GpuPath::Auto) return {requested, "asked for"};
  const gpu::PathChoice choice = gpu::choose_calibrated_path(context, preview_calibration_kind(), cache, calibrate);
  return {choice.first ? GpuPath::Compute : GpuPath::Raster, choice.reason};
}

GpuPathChoice choose_gpu_path(gpu::Context& context, GpuPath requested) {
  return choose_gpu_path(context, requested, gpu::calibration_cache_path(preview_calibration_kind()),
                         [&context] { return calibrate_gpu_path(context); });
}

}  // namespace ts::preview
