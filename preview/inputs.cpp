#include "preview/inputs.h"

#include <algorithm>
#include <cmath>

#include "body/body_file.h"
#include "body/particles_ply.h"
#include "core/error.h"
#include "sampler/point_grid.h"

namespace ts::preview {

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::vector<Eigen::Vector3d> to_double(const std::vector<Eigen::Vector3f>& points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(p.cast<double>());
  return out;
}

}  // namespace

double estimate_radius(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 2) return 0.0;
  Aabb box;
  for (const auto& p : points) box.extend(p);
  const Eigen::Vector3d e = box.size();
  // About the spacing of points spread over the box's surface; the grid is exact for any cell.
  const double area = 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
  double cell = std::sqrt(area / static_cast<double>(points.size()));
  if (!(cell > 0.0)) cell = std::max(e.maxCoeff() / std::cbrt(static_cast<double>(points.size())), 1e-9);
  const sampler::PointGrid grid(points, cell);
  std::vector<double> nearest(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) nearest[i] = grid.nearest(points[i], i).distance;
  const auto middle = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
  std::nth_element(nearest.begin(), middle, nearest.end());
  return 0.5 * *middle;
}

LoadedParticles load_particles(const std::filesystem::path& file, double radius) {
  LoadedParticles out;
  const std::string name = file.filename().string();
  if (ends_with(name, ".json")) {
    const body::ParticleBody body = body::read_body(file);
    out.particles.centers = to_double(body.positions);
    out.sampled_radius = body.particle_radius;
    out.radius_source = "body.json";
  } else {
    out.particles.centers = to_double(body::read_particles_ply(file).positions);
    if (out.particles.centers.empty()) throw InputError(file, "holds no particles");
    // NAME.particles.ply: the NAME.body.json beside it knows the radius.
    const std::string suffix = ".particles.ply";
    const std::filesystem::path beside =
        ends_with(name, suffix)
            ? file.parent_path() / (name.substr(0, name.size() - suffix.size()) + ".body.json")
            : std::filesystem::path();
    if (!beside.empty() && std::filesystem::exists(beside)) {
      out.sampled_radius = body::read_body(beside).particle_radius;
      out.radius_source = "body.json";
    } else {
      out.sampled_radius = estimate_radius(out.particles.centers);
      out.radius_source = "estimated from the spacing";
      if (!(out.sampled_radius > 0.0) && !(radius > 0.0)) {
        throw InputError(file,
                         "cannot estimate a particle radius from a single particle or coincident ones: "
                         "give --particle-radius");
      }
    }
  }
  if (radius > 0.0) out.radius_source = "--particle-radius";
  out.particles.radii = {static_cast<float>(radius > 0.0 ? radius : out.sampled_radius)};
  return out;
}

}  // namespace ts::preview
