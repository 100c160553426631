#include "preview/frame_walls.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace ts::preview {
namespace {

// A floor is left to the renderer's ground plane: normal within 25 degrees of +z.
bool is_floor(const Eigen::Vector3d& normal) {
  return normal.z() > std::cos(25.0 * std::numbers::pi / 180.0);
}

// The top a wall is framed up to: its own, or the content's if lower (never below the wall's floor).
double framed_top(double wall_min, double wall_max, const Aabb& content) {
  if (!content.valid()) return wall_max;
  return std::min(wall_max, std::max(content.max.z(), wall_min));
}

std::array<Eigen::Vector3d, 8> corners(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  std::array<Eigen::Vector3d, 8> c;
  for (int i = 0; i < 8; ++i)
    c[i] = {i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z()};
  return c;
}

// Projects world points into pixel coordinates (top row first) of a perspective camera.
struct Projector {
  Projector(const Camera& camera, int image_width, int image_height)
      : eye(camera.eye),
        forward(camera.forward()),
        right(camera.right()),
        up(camera.image_up()),
        tan_half(std::tan(0.5 * camera.fov_y * std::numbers::pi / 180.0)),
        aspect(static_cast<double>(image_width) / image_height),
        width(image_width),
        height(image_height) {}

  Eigen::Vector3d eye_space(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - eye;
    return {d.dot(right), d.dot(up), d.dot(forward)};
  }
  Eigen::Vector2d pixel(const Eigen::Vector3d& e) const {
    const double ndc_x = e.x() / (e.z() * tan_half * aspect), ndc_y = e.y() / (e.z() * tan_half);
    return {(0.5 * ndc_x + 0.5) * width, (0.5 - 0.5 * ndc_y) * height};
  }
  // The unit view ray through the centre of pixel (x, y).
  Eigen::Vector3d ray(int x, int y) const {
    const double ndc_x = 2.0 * (x + 0.5) / width - 1.0, ndc_y = 1.0 - 2.0 * (y + 0.5) / height;
    return (forward + ndc_x * tan_half * aspect * right + ndc_y * tan_half * up).normalized();
  }

  Eigen::Vector3d eye, forward, right, up;
  double tan_half, aspect;
  int width, height;
};

// Liang-Barsky: clips the segment a-b to the rectangle [lo, hi]; false when nothing is left.
bool clip_2d(Eigen::Vector2d& a, Eigen::Vector2d& b, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector2d d = b - a;
  for (int k = 0; k < 2; ++k) {
    for (const auto& [p, q] : {std::pair{-d[k], a[k] - lo[k]}, std::pair{d[k], hi[k] - a[k]}}) {
      if (p == 0.0) {
        if (q < 0.0) return false;
        continue;
      }
      const double t = q / p;
      if (p < 0.0)
        t0 = std::max(t0, t);
      else
        t1 = std::min(t1, t);
    }
  }
  if (t0 > t1) return false;
  const Eigen::Vector2d start = a + t0 * d;
  b = a + t1 * d;
  a = start;
  return true;
}

void blend(std::uint8_t* px, const Eigen::Vector3f& srgb, float alpha) {
  for (int k = 0; k < 3; ++k) {
    const float v = (1.0f - alpha) * px[k] + alpha * 255.0f * srgb[k];
    px[k] = static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 255.0f)));
  }
  px[3] = 255;
}

// The content's box widened by 5 % of its diagonal, so that a plane bounding the grains cuts it.
Aabb widened(const Aabb& content) {
  if (!content.valid()) return content;
  Aabb box = content;
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(0.05 * content.size().norm());
  box.min -= margin;
  box.max += margin;
  return box;
}

}  // namespace

std::vector<Eigen::Vector3d> clip_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                                        const Aabb& box) {
  std::vector<Eigen::Vector3d> out;
  if (!box.valid()) return out;
  const auto c = corners(box.min, box.max);
  // The twelve edges: corner pairs differing in one bit.
  for (int i = 0; i < 8; ++i) {
    for (int bit = 1; bit < 8; bit <<= 1) {
      if (i & bit) continue;
      const double da = normal.dot(c[i] - point), db = normal.dot(c[i | bit] - point);
      if ((da < 0) == (db < 0) || da == db) continue;
      out.push_back(c[i] + da / (da - db) * (c[i | bit] - c[i]));
    }
  }
  if (out.size() < 3) return {};
  // In order around the centroid, by angle in the plane.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : out) centre += p;
  centre /= static_cast<double>(out.size());
  const Eigen::Vector3d t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
  std::sort(out.begin(), out.end(), [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2((a - centre).dot(t2), (a - centre).dot(t1)) <
           std::atan2((b - centre).dot(t2), (b - centre).dot(t1));
  });
  return out;
}

FrameWalls::FrameWalls(const scene::Scene& scene) {
  for (const scene::Boundary& b : scene.boundaries) {
    switch (b.type) {
      case scene::BoundaryType::Box:
        boxes_.push_back(b);
        break;
      case scene::BoundaryType::Cylinder:
        cylinders_.push_back(b);
        break;
      case scene::BoundaryType::Plane:
        if (!is_floor(b.normal)) {
          planes_.push_back(b);
        } else {
          floor_level_ = std::min(floor_level_.value_or(b.point.z()), b.point.z());
        }
        break;
    }
  }
  for (const scene::Boundary& b : boxes_) floor_level_ = std::min(floor_level_.value_or(b.min.z()), b.min.z());
}

Aabb FrameWalls::framing_box(const Aabb& content) const {
  Aabb box;
  for (const scene::Boundary& b : boxes_) {
    box.extend(b.min);
    box.extend(Eigen::Vector3d(b.max.x(), b.max.y(), framed_top(b.min.z(), b.max.z(), content)));
  }
  for (const scene::Boundary& b : cylinders_) {
    box.extend(Eigen::Vector3d(b.axis.x() - b.radius, b.axis.y() - b.radius, b.z_min));
    box.extend(
        Eigen::Vector3d(b.axis.x() + b.radius, b.axis.y() + b.radius, framed_top(b.z_min, b.z_max, content)));
  }
  for (const scene::Boundary& b : planes_) {
    for (const Eigen::Vector3d& p : clip_plane(b.point, b.normal, widened(content))) box.extend(p);
  }
  if (floor_level_ && content.valid()) {
    const Eigen::Vector3d c = content.center();
    box.extend(Eigen::Vector3d(c.x(), c.y(), *floor_level_));
  }
  return box;
}

std::vector<Segment> FrameWalls::outlines(const Aabb& content) const {
  std::vector<Segment> out;
  for (const scene::Boundary& b : boxes_) {
    const auto c = corners(b.min, b.max);
    for (int i = 0; i < 8; ++i)
      for (int bit = 1; bit < 8; bit <<= 1)
        if (!(i & bit)) out.push_back({c[i], c[i | bit]});
  }
  constexpr int kRimSegments = 64;
  for (const scene::Boundary& b : cylinders_) {
    for (const double z : {b.z_min, b.z_max}) {
      for (int k = 0; k < kRimSegments; ++k) {
        const auto at = [&](int j) {
          const double a = 2.0 * std::numbers::pi * j / kRimSegments;
          return Eigen::Vector3d(b.axis.x() + b.radius * std::cos(a), b.axis.y() + b.radius * std::sin(a), z);
        };
        out.push_back({at(k), at(k + 1)});
      }
    }
  }
  for (const scene::Boundary& b : planes_) {
    const auto polygon = clip_plane(b.point, b.normal, widened(content));
    for (std::size_t k = 0; k < polygon.size(); ++k)
      out.push_back({polygon[k], polygon[(k + 1) % polygon.size()]});
  }
  return out;
}

std::optional<double> FrameWalls::far_wall(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  std::optional<double> nearest;
  const auto keep = [&](double t) {
    if (t > 0 && (!nearest || t < *nearest)) nearest = t;
  };
  for (const scene::Boundary& b : boxes_) {
    // Slabs: where the ray leaves the box, and along which axis.
    double t_in = -1e300, t_out = 1e300;
    int exit_axis = -1;
    for (int k = 0; k < 3; ++k) {
      if (d[k] == 0.0) {
        if (o[k] < b.min[k] || o[k] > b.max[k]) t_out = -1e300;
        continue;
      }
      double t0 = (b.min[k] - o[k]) / d[k], t1 = (b.max[k] - o[k]) / d[k];
      if (t0 > t1) std::swap(t0, t1);
      t_in = std::max(t_in, t0);
      if (t1 < t_out) t_out = t1, exit_axis = k;
    }
    if (t_out > t_in && exit_axis >= 0 && exit_axis < 2)
      keep(t_out);  // a side wall, not the floor or the open top
  }
  for (const scene::Boundary& b : cylinders_) {
    const Eigen::Vector2d p = o.head<2>() - b.axis, v = d.head<2>();
    const double a = v.squaredNorm(), h = p.dot(v), c = p.squaredNorm() - b.radius * b.radius;
    const double disc = h * h - a * c;
    if (a == 0.0 || disc < 0.0) continue;
    const double t = (-h + std::sqrt(disc)) / a;  // the far crossing
    const double z = o.z() + t * d.z();
    if (z >= b.z_min && z <= b.z_max) keep(t);
  }
  return nearest;
}

void draw_walls(Image& image, const std::vector<Layer>& layers, const Camera& camera, const FrameWalls& walls,
                const Aabb& content, std::optional<double> ground_level, const WallStyle& style) {
  if (walls.empty()) return;
  const Projector proj(camera, image.width, image.height);
  const auto background = [&](int x, int y) {
    return layers.empty() || layers[static_cast<std::size_t>(y) * image.width + x] == Layer::Background;
  };
  // 1. The far walls, behind everything drawn, in front of the ground.
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (!background(x, y)) continue;
      const Eigen::Vector3d d = proj.ray(x, y);
      const auto t = walls.far_wall(camera.eye, d);
      if (!t) continue;
      if (ground_level && d.z() < 0) {
        const double t_ground = (*ground_level - camera.eye.z()) / d.z();
        if (t_ground > 0 && t_ground < *t * (1 - 1e-9)) continue;
      }
      blend(image.pixel(x, y), style.color, style.tint);
    }
  }
  // 2. The outlines, clipped to the space in front of the eye and to the image.
  const double near = 1e-3 * std::max(content.valid() ? content.size().norm() : 1.0, 1e-6);
  const int thickness = std::max(1, image.height / 480);
  std::vector<std::uint8_t> line(static_cast<std::size_t>(image.width) * image.height, 0);
  for (const Segment& s : walls.outlines(content)) {
    Eigen::Vector3d a = proj.eye_space(s.a), b = proj.eye_space(s.b);
    if (a.z() < near && b.z() < near) continue;
    if (a.z() < near) a += (near - a.z()) / (b.z() - a.z()) * (b - a);
    if (b.z() < near) b += (near - b.z()) / (a.z() - b.z()) * (a - b);
    Eigen::Vector2d pa = proj.pixel(a), pb = proj.pixel(b);
    if (!clip_2d(pa, pb, Eigen::Vector2d(0, 0), Eigen::Vector2d(image.width - 1e-6, image.height - 1e-6)))
      continue;
    const int steps = std::max(1, static_cast<int>(std::ceil((pb - pa).cwiseAbs().maxCoeff())));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = pa + (pb - pa) * (static_cast<double>(k) / steps);
      for (int dy = 0; dy < thickness; ++dy) {
        for (int dx = 0; dx < thickness; ++dx) {
          const int x = static_cast<int>(p.x()) + dx, y = static_cast<int>(p.y()) + dy;
          if (x < image.width && y < image.height) line[static_cast<std::size_t>(y) * image.width + x] = 1;
        }
      }
    }
  }
  // Each pixel of a line blended once, however many lines cross it.
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (line[static_cast<std::size_t>(y) * image.width + x])
        blend(image.pixel(x, y), style.color, background(x, y) ? 1.0f : style.over_content);
}

}  // namespace ts::preview
