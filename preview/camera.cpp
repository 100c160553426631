#include "preview/camera.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace ts::preview {

namespace {

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// The front axis for a world up axis: +z (y-up meshes) unless up is near z, then -y (z-up scenes).
Eigen::Vector3d front_axis(const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d candidate =
      std::abs(u.z()) < 0.9 ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(0, -1, 0);
  return (candidate - candidate.dot(u) * u).normalized();
}

std::array<Eigen::Vector3d, 8> corners(const Aabb& box) {
  std::array<Eigen::Vector3d, 8> c;
  for (int i = 0; i < 8; ++i) {
    c[i] = Eigen::Vector3d(i & 1 ? box.max.x() : box.min.x(), i & 2 ? box.max.y() : box.min.y(),
                           i & 4 ? box.max.z() : box.min.z());
  }
  return c;
}

// The offset across the view that centres points at coordinates c_i (along one image axis) seen from
// depths d_i > 0: f(a) = max (c_i - a) / d_i + min (c_i - a) / d_i (the projections' two extremes)
// falls as a grows, from >= 0 at the smallest c_i to <= 0 at the largest; bisection finds its root.
double centred_offset(const std::vector<double>& c, const std::vector<double>& depth) {
  if (c.empty()) return 0.0;
  double lo = *std::min_element(c.begin(), c.end()), hi = *std::max_element(c.begin(), c.end());
  for (int k = 0; k < 100 && hi - lo > 0.0; ++k) {
    const double a = 0.5 * (lo + hi);
    double most = -1e300, least = 1e300;
    for (std::size_t i = 0; i < c.size(); ++i) {
      most = std::max(most, (c[i] - a) / depth[i]);
      least = std::min(least, (c[i] - a) / depth[i]);
    }
    (most + least > 0.0 ? lo : hi) = a;
  }
  return 0.5 * (lo + hi);
}

// For a camera looking along -back at `center` with axes (right, up): the distance (perspective) or
// the visible height (orthographic) that holds every corner.
double fit(const std::array<Eigen::Vector3d, 8>& points, const Eigen::Vector3d& center,
           const Eigen::Vector3d& back, const Eigen::Vector3d& up, double aspect, bool ortho, double fov_y) {
  const Eigen::Vector3d right = up.cross(back).normalized();
  const Eigen::Vector3d image_up = back.cross(right);
  const double tan_y = std::tan(0.5 * radians(fov_y)), tan_x = tan_y * aspect;
  double need = 0.0;
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - center;
    const double x = std::abs(d.dot(right)), y = std::abs(d.dot(image_up)), z = d.dot(back);
    if (ortho) {
      need = std::max({need, 2.0 * y, 2.0 * x / aspect});
    } else {
      // |x| / (distance - z) <= tan_x and the same for y.
      need = std::max({need, z + x / tan_x, z + y / tan_y});
    }
  }
  return need;
}

}  // namespace

View parse_view(const std::string& name) {
  if (name == "front") return View::Front;
  if (name == "side") return View::Side;
  if (name == "top") return View::Top;
  if (name == "iso") return View::Iso;
  throw InputError("unknown view '" + name + "' (expected front, side, top or iso)");
}

Eigen::Vector3d view_direction(View view, const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized(), f = front_axis(up), s = u.cross(f);
  switch (view) {
    case View::Front:
      return f;
    case View::Side:
      return s;
    case View::Top:
      return u;
    case View::Iso:
      return (f + s + u).normalized();
  }
  return f;
}

Eigen::Vector3d view_image_up(View view, const Eigen::Vector3d& up) {
  return view == View::Top ? Eigen::Vector3d(-front_axis(up)) : Eigen::Vector3d(up.normalized());
}

Eigen::Vector3d view_direction(double azimuth, double elevation, const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized(), f = front_axis(up), s = u.cross(f);
  const double a = radians(azimuth), e = radians(elevation);
  return (std::cos(e) * (std::cos(a) * f + std::sin(a) * s) + std::sin(e) * u).normalized();
}

Eigen::Vector3d Camera::forward() const { return (target - eye).normalized(); }
Eigen::Vector3d Camera::right() const { return forward().cross(up).normalized(); }
Eigen::Vector3d Camera::image_up() const { return right().cross(forward()); }

void validate(const Camera& c) {
  if (!c.eye.allFinite() || !c.target.allFinite() || !c.up.allFinite()) {
    throw InputError("camera: eye, target and up must be finite");
  }
  const Eigen::Vector3d view = c.target - c.eye;
  if (!(view.norm() > 0.0)) throw InputError("camera: the eye and the target are the same point");
  if (!(c.up.norm() > 0.0) || view.normalized().cross(c.up.normalized()).norm() < 1e-6) {
    throw InputError("camera: the up vector is zero or parallel to the view direction");
  }
  if (!c.ortho && !(c.fov_y > 0.0 && c.fov_y < 180.0)) {
    throw InputError("camera: the field of view must lie between 0 and 180 degrees");
  }
  if (c.ortho && !(c.ortho_height > 0.0 && std::isfinite(c.ortho_height))) {
    throw InputError("camera: the orthographic height must be positive");
  }
}

Camera frame_box(const Aabb& box, const Eigen::Vector3d& from, const Eigen::Vector3d& up, double aspect,
                 bool ortho, double fov_y, int turntable_frames, const Eigen::Vector3d& orbit_axis,
                 double margin) {
  const auto points = corners(box);
  const Eigen::Vector3d center = box.center();
  const Eigen::Vector3d back = from.normalized();
  double need = 0.0;
  const int frames = std::max(1, turntable_frames);
  for (int k = 0; k < frames; ++k) {
    const Eigen::AngleAxisd turn(2.0 * std::numbers::pi * k / frames, orbit_axis.normalized());
    need = std::max(need, fit(points, center, turn * back, turn * up, aspect, ortho, fov_y));
  }
  // A point-like box (one particle, say) still gets a finite view.
  need = std::max(need, 1e-9 * std::max(1.0, center.norm()));
  Camera camera;
  camera.target = center;
  camera.up = up;
  camera.fov_y = fov_y;
  camera.ortho = ortho;
  if (ortho) {
    camera.ortho_height = margin * need;
    camera.eye = center + back * std::max(box.size().norm(), camera.ortho_height);
  } else {
    camera.eye = center + back * (margin * need);
  }
  return camera;
}

Camera frame_points(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& from,
                    const Eigen::Vector3d& up, double aspect, double fov_y, double margin) {
  const Eigen::Vector3d back = from.normalized(), right = up.cross(back).normalized(),
                        image_up = back.cross(right);
  const double tan_y = std::tan(0.5 * radians(fov_y)) / margin, tan_x = tan_y * aspect;
  // Coordinates relative to the points' mean, so far-off scenes keep their precision.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const auto& p : points) origin += p;
  origin /= std::max<double>(1.0, static_cast<double>(points.size()));
  // Eye = origin + a right + b image_up + w back. A point at (x, y, z) along (right, image_up, back)
  // lies inside the frustum when |x - a| <= tan_x (w - z) and |y - b| <= tan_y (w - z), that is
  // w >= z + (x - a) / tan_x and w >= z - (x - a) / tan_x. Over all points the smallest w is
  // max(P - a / tan_x, M + a / tan_x), P = max(z + x / tan_x), M = max(z - x / tan_x): least where
  // both are equal, w = (P + M) / 2. The same holds along y; the eye needs the larger of the two w,
  // and then along each axis the offset that centres the points' projections.
  double px = -1e300, mx = -1e300, py = -1e300, my = -1e300, nearest = 1e300, farthest = -1e300;
  std::vector<double> xs, ys, zs;
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - origin;
    xs.push_back(d.dot(right)), ys.push_back(d.dot(image_up)), zs.push_back(d.dot(back));
    px = std::max(px, zs.back() + xs.back() / tan_x), mx = std::max(mx, zs.back() - xs.back() / tan_x);
    py = std::max(py, zs.back() + ys.back() / tan_y), my = std::max(my, zs.back() - ys.back() / tan_y);
    nearest = std::min(nearest, zs.back()), farthest = std::max(farthest, zs.back());
  }
  double w = std::max(0.5 * (px + mx), 0.5 * (py + my));
  // A point-like set (one particle, say) still gets a finite view, with every point in front of the eye.
  w = std::max(w, farthest + 1e-9 * std::max(1.0, origin.norm()));
  std::vector<double> depths(zs.size());
  for (std::size_t i = 0; i < zs.size(); ++i) depths[i] = w - zs[i];
  const double a = centred_offset(xs, depths), b = centred_offset(ys, depths);
  Camera camera;
  camera.eye = origin + a * right + b * image_up + w * back;
  // The target on the view axis, at the depth of the points' middle.
  camera.target = camera.eye - (w - 0.5 * (nearest + farthest)) * back;
  camera.up = up;
  camera.fov_y = fov_y;
  return camera;
}

Camera frame_box_tightly(const Aabb& box, const Eigen::Vector3d& from, const Eigen::Vector3d& up,
                         double aspect, double fov_y, double margin) {
  const auto c = corners(box);
  return frame_points(std::vector<Eigen::Vector3d>(c.begin(), c.end()), from, up, aspect, fov_y, margin);
}

Camera orbit(const Camera& camera, const Eigen::Vector3d& axis, double angle) {
  const Eigen::AngleAxisd turn(angle, axis.normalized());
  Camera out = camera;
  out.eye = camera.target + turn * (camera.eye - camera.target);
  out.up = turn * camera.up;
  return out;
}

ViewMatrices view_matrices(const Camera& camera, double aspect, const Eigen::Vector3d& center,
                           double radius) {
  ViewMatrices m;
  const Eigen::Vector3d f = camera.forward(), r = camera.right(), u = camera.image_up();
  m.view.row(0) << r.transpose(), -r.dot(camera.eye);
  m.view.row(1) << u.transpose(), -u.dot(camera.eye);
  m.view.row(2) << -f.transpose(), f.dot(camera.eye);
  m.view.row(3) << 0, 0, 0, 1;
  // Near and far hug the bounding sphere; a pinhole's near plane stays in front of the eye.
  const double depth = (center - camera.eye).dot(f);
  const double slack = 1e-3 * std::max(radius, 1e-12);
  m.far = depth + radius + slack;
  m.near = depth - radius - slack;
  if (!camera.ortho) m.near = std::max(m.near, 1e-4 * m.far);
  if (!(m.far > m.near)) m.far = m.near + 1.0;
  const double n = m.near, fa = m.far;
  m.projection.setZero();
  if (camera.ortho) {
    const double h = 0.5 * camera.ortho_height, w = h * aspect;
    m.projection(0, 0) = 1.0 / w;
    m.projection(1, 1) = 1.0 / h;
    m.projection(2, 2) = -2.0 / (fa - n);
    m.projection(2, 3) = -(fa + n) / (fa - n);
    m.projection(3, 3) = 1.0;
  } else {
    const double t = 1.0 / std::tan(0.5 * radians(camera.fov_y));
    m.projection(0, 0) = t / aspect;
    m.projection(1, 1) = t;
    m.projection(2, 2) = -(fa + n) / (fa - n);
    m.projection(2, 3) = -2.0 * fa * n / (fa - n);
    m.projection(3, 2) = -1.0;
  }
  return m;
}

}  // namespace ts::preview
