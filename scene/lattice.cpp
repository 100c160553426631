// The lattice that emitters place grains on before they release them: a jittered cubic lattice whose
// spacing keeps any two grains apart whatever their orientation. Shared by the world builder
// (scene/scene_world.cpp) and the size checks that run before it (scene/scene_limits.cpp).
#include "scene/lattice.h"

#include <fmt/format.h>

#include "core/error.h"

namespace ts::scene {
namespace {


// Grains are spaced 10 % beyond their bounding diameter (2.22 d for touching spheres) and jittered
// by at most 2 % of the spacing per axis, so no two start in contact whatever their orientation.
constexpr double kSiteMargin = 1.1;
constexpr double kJitter = 0.02;

}  // namespace

double lattice_spacing(double bound) { return 2 * bound * kSiteMargin; }

double lattice_site_count(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double bound) {
  const Eigen::Vector3d lo = min.array() + bound * kSiteMargin, hi = max.array() - bound * kSiteMargin;
  if (!(hi.array() >= lo.array()).all()) return 0;
  const Eigen::Array3d n = ((hi - lo) / lattice_spacing(bound)).array().floor() + 1;
  return n.prod();
}

std::vector<Eigen::Vector3d> grain_sites_in_box(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double bound,
                                                std::mt19937_64& rng) {
  const double spacing = lattice_spacing(bound);  // m
  const Eigen::Vector3d lo = min.array() + bound * kSiteMargin, hi = max.array() - bound * kSiteMargin;
  if (!(hi.array() >= lo.array()).all()) return {};
  // Scenes are checked before (check_scene_sizes); this guards the int casts for other callers.
  const double count = lattice_site_count(min, max, bound);
  if (!(count <= kMaxLatticeSites)) {
    throw InputError(
        fmt::format("a box of {:.3g} lattice sites: at most {:.0f} fit", count, kMaxLatticeSites));
  }
  const Eigen::Vector3i n = ((hi - lo) / spacing).array().floor().cast<int>() + 1;
  std::uniform_real_distribution<double> jitter(-kJitter * spacing, kJitter * spacing);
  std::vector<Eigen::Vector3d> sites;
  sites.reserve(static_cast<std::size_t>(n.x()) * n.y() * n.z());
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) {
        const Eigen::Vector3d jittered(jitter(rng), jitter(rng), jitter(rng));
        sites.push_back(lo + spacing * Eigen::Vector3d(i, j, k) + jittered);
      }
    }
  }
  return sites;
}

}  // namespace ts::scene
