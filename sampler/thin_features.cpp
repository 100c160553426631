#include "sampler/thin_features.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <unordered_map>
#include <utility>

#include "core/union_find.h"

namespace ts::sampler {
namespace {

// The detector's question at spacing s (sampler/thin_features.h): is the point half a spacing inward
// from the centroid at least s / 4 deep in the solid?
bool passes(const sdf::ExactDistance& exact, const Eigen::Vector3d& centroid, const Eigen::Vector3d& normal,
            double s) {
  const Eigen::Vector3d probe = centroid - 0.5 * s * normal;
  return exact.signed_distance(probe, sdf::SignMethod::Pseudonormal) <= -0.25 * s;
}

Eigen::Vector3d centroid_of(const TriangleMesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles[t];
  return (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3.0;
}

double triangle_area(const TriangleMesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles[t];
  const Eigen::Vector3d& a = mesh.vertices[tri[0]];
  return 0.5 * (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a).norm();
}

// The largest spacing below `spacing` at which a thin triangle passes, searched in kScanSteps steps
// down from it, then by bisection: kThinOverSpacing times it is the triangle's local thickness, that
// of a slab or a rod exactly (also for a triangle on its rim, off the middle: there the probe reaches
// the far face sideways, at the same spacing). The passing end of the bracket is kept, so a thickness
// errs small. 0: it does not pass even at spacing / kScanSteps (a sliver or a knife edge).
constexpr int kScanSteps = 64;
constexpr int kBisections = 12;
double passing_spacing(const sdf::ExactDistance& exact, const Eigen::Vector3d& centroid,
                       const Eigen::Vector3d& normal, double spacing) {
  const double step = spacing / kScanSteps;
  int k = kScanSteps - 1;
  while (k > 0 && !passes(exact, centroid, normal, k * step)) --k;
  if (k == 0) return 0.0;
  double lo = k * step, hi = (k + 1) * step;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    (passes(exact, centroid, normal, mid) ? lo : hi) = mid;
  }
  return lo;
}

// Thin triangles grouped by shared vertices: region index per thin triangle, in order of first use.
std::vector<std::uint32_t> connected_regions(const TriangleMesh& mesh, const std::vector<std::uint32_t>& thin,
                                             std::size_t& region_count) {
  UnionFind sets(thin.size());
  std::unordered_map<std::uint32_t, std::uint32_t> first_at_vertex;
  for (std::uint32_t k = 0; k < thin.size(); ++k) {
    for (const std::uint32_t v : mesh.triangles[thin[k]]) {
      const auto [it, fresh] = first_at_vertex.emplace(v, k);
      if (!fresh) sets.unite(k, it->second);
    }
  }
  std::unordered_map<std::uint32_t, std::uint32_t> index_of_root;
  std::vector<std::uint32_t> region(thin.size());
  for (std::uint32_t k = 0; k < thin.size(); ++k) {
    const auto [it, fresh] =
        index_of_root.emplace(sets.find(k), static_cast<std::uint32_t>(index_of_root.size()));
    region[k] = it->second;
  }
  region_count = index_of_root.size();
  return region;
}

// The thickness [m] at which the thinner triangles of a region (thickness, area pairs) first hold
// `share` of its area: every triangle at least that thick holds the other 1 - share or more.
double thickness_at_area_share(std::vector<std::pair<double, double>> pieces, double share) {
  std::sort(pieces.begin(), pieces.end());
  double total = 0.0, below = 0.0;
  for (const auto& p : pieces) total += p.second;
  for (const auto& [thickness, area] : pieces) {
    below += area;
    if (below >= share * total) return thickness;
  }
  return pieces.back().first;
}

// The regions of the thin triangles `thin` (local thicknesses `thickness` [m]), largest area first.
ThinFeatures summarise_regions(const TriangleMesh& mesh, const std::vector<std::uint32_t>& thin,
                               const std::vector<double>& thickness, double spacing, double radius) {
  ThinFeatures out;
  out.threshold = kThinOverSpacing * spacing;
  out.triangles = thin.size();
  std::size_t count = 0;
  const std::vector<std::uint32_t> region = connected_regions(mesh, thin, count);
  out.regions.assign(count, ThinRegion{});
  std::vector<std::vector<std::pair<double, double>>> pieces(count);  // (thickness, area) per region
  for (std::size_t k = 0; k < thin.size(); ++k) {
    ThinRegion& r = out.regions[region[k]];
    for (const std::uint32_t v : mesh.triangles[thin[k]]) r.box.extend(mesh.vertices[v]);
    ++r.triangles;
    pieces[region[k]].emplace_back(thickness[k], triangle_area(mesh, thin[k]));
    r.area += pieces[region[k]].back().second;
    out.where.extend(centroid_of(mesh, thin[k]));
  }
  const double total_area = surface_area(mesh);
  const double radius_per_thickness = kResolvingMargin * radius / (kThinOverSpacing * spacing);
  for (std::size_t g = 0; g < count; ++g) {
    ThinRegion& r = out.regions[g];
    r.area_share = r.area / total_area;
    r.thinnest = thickness_at_area_share(pieces[g], 0.0);
    r.resolving_radius = radius_per_thickness * r.thinnest;
    r.mostly_resolving_radius =
        radius_per_thickness * thickness_at_area_share(pieces[g], 1.0 - kMostlyResolved);
    out.area_share += r.area_share;
  }
  std::stable_sort(out.regions.begin(), out.regions.end(),
                   [](const ThinRegion& a, const ThinRegion& b) { return a.area > b.area; });
  return out;
}

}  // namespace

std::string resolving_radii_text(const ThinRegion& region) {
  const auto radius = [](double r) {
    return r > 0.0 ? fmt::format("--radius {:.3g}", r) : std::string("no radius");
  };
  if (region.mostly_resolving_radius == region.resolving_radius) {
    return region.resolving_radius > 0.0 ? radius(region.resolving_radius) + " resolves all of it"
                                         : "no radius resolves it (a knife edge or a sliver)";
  }
  return fmt::format("{} resolves {:.0f} % of it, {} all of it{}", radius(region.mostly_resolving_radius),
                     100.0 * kMostlyResolved, radius(region.resolving_radius),
                     region.resolving_radius > 0.0 ? "" : " (a knife edge or a sliver)");
}

std::string local_radius_advice() {
  return "a smaller radius on these regions alone is not offered (a body has one particle radius; "
         "docs/body-format.md, \"Thin features\"): a smaller --radius or a larger --count resolves them";
}

ThinFeatures find_thin_features(const TriangleMesh& mesh, const sdf::ExactDistance& exact, double spacing,
                                double radius) {
  const sdf::Pseudonormals& pn = exact.pseudonormals();
  std::vector<std::uint8_t> flagged(mesh.triangle_count(), 0);
  tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) {
    flagged[t] = passes(exact, centroid_of(mesh, t), pn.face[t], spacing) ? 0 : 1;
  });
  std::vector<std::uint32_t> thin;
  for (std::uint32_t t = 0; t < flagged.size(); ++t)
    if (flagged[t]) thin.push_back(t);
  std::vector<double> thickness(thin.size());
  tbb::parallel_for(std::size_t{0}, thin.size(), [&](std::size_t k) {
    thickness[k] =
        kThinOverSpacing * passing_spacing(exact, centroid_of(mesh, thin[k]), pn.face[thin[k]], spacing);
  });
  return summarise_regions(mesh, thin, thickness, spacing, radius);
}

}  // namespace ts::sampler
