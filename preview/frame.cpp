#include "preview/frame.h"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace ts::preview {
namespace {

Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& v) {
  const Eigen::Vector3d a = std::abs(v.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return v.cross(a).normalized();
}

// The lowest point of a box along the unit vector `up` [m].
double lowest_along(const Aabb& box, const Eigen::Vector3d& up) {
  double lowest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d corner(i & 1 ? box.max.x() : box.min.x(), i & 2 ? box.max.y() : box.min.y(),
                                 i & 4 ? box.max.z() : box.min.z());
    lowest = std::min(lowest, up.dot(corner));
  }
  return lowest;
}

// The key light's shadow map: an orthographic view along the light holding the bounding sphere.
void plan_shadow(const RenderSettings& s, int max_texture, Frame& f) {
  f.shadow_size =
      std::min(s.shadow_map_size > 0 ? s.shadow_map_size : std::clamp(std::max(s.width, s.height), 512, 4096),
               max_texture);
  Camera lc;
  lc.target = f.origin;
  lc.eye = f.origin + f.light * (2.0 * f.radius);
  lc.up = any_perpendicular(f.light);
  lc.ortho = true;
  lc.ortho_height = 2.02 * f.radius;
  f.light_camera = camera_state(lc, f.shadow_size, f.shadow_size, f.origin, f.radius);
  f.shadow_texel = 2.02 * f.radius / f.shadow_size;
  // Light depth is linear over the near-far range (about 2 radius): one texel of slack.
  f.shadow_bias = f.shadow_texel / (2.0 * f.radius);
}

// ts::InputError for a bad camera, up vector or colour map, or nothing to draw.
void check_settings(const RenderSettings& s, const Aabb& content) {
  validate(s.camera);
  if (!(s.up.norm() > 0.0) || !s.up.allFinite())
    throw InputError("the up vector must be finite and non-zero");
  if (!content.valid()) throw InputError("nothing to render: no SDF and no particles");
  if (s.surface_scalar.value && !(s.surface_scalar.max_value > 0.0)) {
    throw InputError("the colour map's top value must be positive");
  }
}

}  // namespace

CameraState camera_state(const Camera& camera, int width, int height, const Eigen::Vector3d& origin, double radius) {
  Camera local = camera;
  local.eye -= origin;
  local.target -= origin;
  const ViewMatrices m =
      view_matrices(local, static_cast<double>(width) / height, Eigen::Vector3d::Zero(), radius);
  CameraState s;
  s.view_projection = m.projection * m.view;
  s.inverse = s.view_projection.inverse();
  s.eye = local.eye;
  s.forward = local.forward();
  s.right = local.right();
  s.up = local.image_up();
  s.ortho = camera.ortho;
  s.width = width;
  s.height = height;
  return s;
}

Aabb content_box(const std::optional<Aabb>& surface, const Aabb& particles) {
  Aabb box;
  if (surface) {
    box.extend(surface->min);
    box.extend(surface->max);
  }
  if (particles.valid()) {
    box.extend(particles.min);
    box.extend(particles.max);
  }
  return box;
}

Aabb particle_box(const Particles& particles) {
  const std::size_t n = particles.centers.size();
  if (n && particles.radii.size() != 1 && particles.radii.size() != n) {
    throw InputError("particles: give one radius, or one per particle");
  }
  if (!particles.colors.empty() && particles.colors.size() != n) throw InputError("particles: one colour per particle");
  Aabb box;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = particles.radii[particles.radii.size() == 1 ? 0 : i];
    if (!particles.centers[i].allFinite() || !(r > 0.0) || !std::isfinite(r)) {
      throw InputError(fmt::format("particle {} has a non-finite position or a radius that is not positive", i));
    }
    box.extend(particles.centers[i] - Eigen::Vector3d::Constant(r));
    box.extend(particles.centers[i] + Eigen::Vector3d::Constant(r));
  }
  return box;
}

Eigen::Vector3d default_light(const Camera& camera, const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  Eigen::Vector3d back = -camera.forward();
  back -= back.dot(u) * u;
  if (back.norm() < 1e-6) {  // looking straight down or up: the image's down is "towards the camera"
    back = -camera.image_up();
    back -= back.dot(u) * u;
  }
  if (back.norm() < 1e-6) back = any_perpendicular(u);
  back.normalize();
  const Eigen::Vector3d right = u.cross(back).normalized();
  return (0.85 * u + 0.5 * back - 0.45 * right).normalized();
}

Frame plan_frame(const RenderSettings& s, const Aabb& content, const std::optional<Aabb>& volume_box,
                 int max_texture) {
  check_settings(s, content);
  Frame f;
  f.content = content;
  // Everything drawn lies in this sphere; positions are drawn relative to its centre.
  Aabb all = content;
  if (volume_box) {
    all.extend(volume_box->min);
    all.extend(volume_box->max);
  }
  f.origin = all.center();
  f.radius = std::max(0.5 * all.size().norm(), 1e-12);
  f.camera = camera_state(s.camera, s.width, s.height, f.origin, f.radius);
  f.up = s.up.normalized();
  f.light = s.light ? s.light->normalized() : default_light(s.camera, f.up);
  if (!f.light.allFinite()) throw InputError("the light direction must be finite and non-zero");
  f.ground_level = s.ground_level.value_or(lowest_along(content, f.up)) - f.up.dot(f.origin);
  const Eigen::Vector3d center = content.center() - f.origin;
  f.ground_center = center - (f.up.dot(center) - f.ground_level) * f.up;
  f.ground_fade = 2.5 * 0.5 * content.size().norm();
  if (s.shadows) plan_shadow(s, max_texture, f);
  return f;
}

ScalarSummary summarize_scalar(const std::vector<double>& values) {
  ScalarSummary summary;
  double sum = 0.0;
  for (double v : values) {
    if (std::isnan(v)) continue;
    ++summary.pixels;
    sum += v;
    summary.max = std::max(summary.max, v);
  }
  if (summary.pixels) summary.mean = sum / static_cast<double>(summary.pixels);
  return summary;
}

}  // namespace ts::preview
