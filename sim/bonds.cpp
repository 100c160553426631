#include "sim/bonds.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/splitmix.h"

namespace ts::sim {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

std::string validate(const BondMaterial& m) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(m.youngs_modulus)) return "youngs_modulus: must be > 0 Pa";
  if (!positive(m.stiffness_ratio)) return "stiffness_ratio: must be > 0 (k_n / k_s; PFC uses 2.5 for rock)";
  if (!positive(m.radius_factor) || m.radius_factor > 1.0) return "radius_factor: must be in (0, 1]";
  if (!positive(m.tensile_strength)) return "tensile_strength: must be > 0 Pa";
  if (!positive(m.shear_strength)) return "shear_strength: must be > 0 Pa";
  if (!std::isfinite(m.strength_spread) || m.strength_spread < 0.0 || m.strength_spread > 1.0) {
    return "strength_spread: must be in [0, 1] (a relative standard deviation)";
  }
  if (!std::isfinite(m.bond_distance) || m.bond_distance < 1.0 || m.bond_distance > 2.0) {
    return "bond_distance: must be in [1, 2] (times r_a + r_b; 1.2 bonds a fill lattice's neighbours)";
  }
  return {};
}

std::size_t BondSet::intact_count() const {
  return static_cast<std::size_t>(std::count(intact.begin(), intact.end(), std::uint8_t{1}));
}

namespace {

using CellKey = std::uint64_t;

// 21 bits a coordinate: cells are a bond's length or more, so 2^21 of them span any prop.
CellKey cell_key(const Eigen::Vector3i& c) {
  const auto bits = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffffull; };
  return bits(c.x()) | (bits(c.y()) << 21) | (bits(c.z()) << 42);
}

Eigen::Vector3i cell_of(const Eigen::Vector3d& p, const Eigen::Vector3d& origin, double cell) {
  return ((p - origin) / cell).array().floor().cast<int>();
}

// A standard normal from (seed, a, b) alone: Box-Muller on two SplitMix64 draws.
double bond_normal(std::uint64_t seed, std::uint32_t a, std::uint32_t b) {
  const std::uint64_t key = splitmix64(seed ^ splitmix64((std::uint64_t{a} << 32) | b));
  const double u1 = (static_cast<double>(splitmix64(key) >> 11) + 0.5) * 0x1.0p-53;
  const double u2 = static_cast<double>(splitmix64(key + 1) >> 11) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

struct SortedCells {
  std::vector<std::pair<CellKey, std::uint32_t>> entries;  // (cell, sphere), sorted
  Eigen::Vector3d origin;
  double cell = 0;
};

SortedCells sort_into_cells(const std::vector<Eigen::Vector3d>& centres, double cell) {
  SortedCells grid;
  grid.cell = cell;
  grid.origin = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  for (const auto& p : centres) grid.origin = grid.origin.cwiseMin(p);
  grid.entries.reserve(centres.size());
  for (std::uint32_t i = 0; i < centres.size(); ++i) {
    grid.entries.emplace_back(cell_key(cell_of(centres[i], grid.origin, cell)), i);
  }
  std::sort(grid.entries.begin(), grid.entries.end());
  return grid;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> bonded_pairs(const std::vector<Eigen::Vector3d>& centres,
                                                                  const std::vector<double>& radii,
                                                                  double bond_distance) {
  const double largest = *std::max_element(radii.begin(), radii.end());
  const SortedCells grid = sort_into_cells(centres, bond_distance * 2.0 * largest);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::uint32_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3i home = cell_of(centres[i], grid.origin, grid.cell);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const CellKey key = cell_key(home + Eigen::Vector3i(dx, dy, dz));
          auto it = std::lower_bound(grid.entries.begin(), grid.entries.end(), std::make_pair(key, 0u));
          for (; it != grid.entries.end() && it->first == key; ++it) {
            const std::uint32_t j = it->second;
            const double reach = bond_distance * (radii[i] + radii[j]);
            if (j > i && (centres[i] - centres[j]).squaredNorm() < reach * reach) pairs.emplace_back(i, j);
          }
        }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace

BondSet build_bonds(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
                    const BondMaterial& material, std::uint64_t seed) {
  if (centres.size() != radii.size()) throw std::invalid_argument("build_bonds: one radius a centre");
  if (centres.size() >= std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("build_bonds: more spheres than 32-bit indices reach");
  }
  BondSet bonds;
  if (centres.empty()) return bonds;
  for (const auto& [i, j] : bonded_pairs(centres, radii, material.bond_distance)) {
    const double factor =
        std::max(kMinStrengthFactor, 1.0 + material.strength_spread * bond_normal(seed, i, j));
    bonds.a.push_back(i);
    bonds.b.push_back(j);
    bonds.tensile_strength.push_back(material.tensile_strength * factor);
    bonds.shear_strength.push_back(material.shear_strength * factor);
    bonds.rest_overlap.push_back(std::max(0.0, radii[i] + radii[j] - (centres[i] - centres[j]).norm()));
  }
  bonds.material.assign(bonds.size(), 0);
  bonds.intact.assign(bonds.size(), 1);
  bonds.state.assign(bonds.size(), BondState<double>{});
  return bonds;
}

void append_bonds(BondSet& bonds, const BondSet& more, std::uint32_t first_particle, std::uint16_t material) {
  for (std::size_t k = 0; k < more.size(); ++k) {
    bonds.a.push_back(more.a[k] + first_particle);
    bonds.b.push_back(more.b[k] + first_particle);
    bonds.material.push_back(material);
    bonds.tensile_strength.push_back(more.tensile_strength[k]);
    bonds.shear_strength.push_back(more.shear_strength[k]);
    bonds.intact.push_back(more.intact[k]);
    bonds.state.push_back(more.state[k]);
    bonds.rest_overlap.push_back(more.rest_overlap[k]);
  }
}

double RestOverlaps::of(std::uint32_t i, std::uint32_t j) const {
  if (offsets.empty()) return 0.0;
  const auto first = partners.begin() + offsets[i], last = partners.begin() + offsets[i + 1];
  const auto it = std::lower_bound(first, last, j);
  return it != last && *it == j ? overlap[static_cast<std::size_t>(it - partners.begin())] : 0.0;
}

RestOverlaps rest_overlaps(const BondSet& bonds, std::size_t particles) {
  RestOverlaps out;
  if (std::none_of(bonds.rest_overlap.begin(), bonds.rest_overlap.end(), [](double o) { return o > 0.0; })) return out;
  out.offsets.assign(particles + 1, 0u);
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (bonds.rest_overlap[k] <= 0.0) continue;
    ++out.offsets[bonds.a[k] + 1];
    ++out.offsets[bonds.b[k] + 1];
  }
  for (std::size_t i = 0; i < particles; ++i) out.offsets[i + 1] += out.offsets[i];
  out.partners.resize(out.offsets[particles]);
  out.overlap.resize(out.offsets[particles]);
  std::vector<std::uint32_t> next(out.offsets.begin(), out.offsets.end() - 1);
  // Bonds ascend in (a, b) with a < b, so a particle's partners below it (as b) come in ascending a,
  // and those above (as a) in ascending b, but the two runs interleave: sort each list after.
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (bonds.rest_overlap[k] <= 0.0) continue;
    for (const auto& [self, other] : {std::pair{bonds.a[k], bonds.b[k]}, std::pair{bonds.b[k], bonds.a[k]}}) {
      out.partners[next[self]] = other;
      out.overlap[next[self]++] = bonds.rest_overlap[k];
    }
  }
  for (std::size_t i = 0; i < particles; ++i) {
    std::vector<std::pair<std::uint32_t, double>> row;
    for (std::uint32_t e = out.offsets[i]; e < out.offsets[i + 1]; ++e) row.emplace_back(out.partners[e], out.overlap[e]);
    std::sort(row.begin(), row.end());
    for (std::uint32_t e = out.offsets[i]; e < out.offsets[i + 1]; ++e) {
      out.partners[e] = row[e - out.offsets[i]].first;
      out.overlap[e] = row[e - out.offsets[i]].second;
    }
  }
  return out;
}

bool BondedPartners::bonded(std::uint32_t i, std::uint32_t j) const {
  const auto first = partners.begin() + offsets[i], last = partners.begin() + offsets[i + 1];
  return std::binary_search(first, last, j);
}

BondedPartners bonded_partners(const BondSet& bonds, std::size_t particles) {
  BondedPartners out;
  if (bonds.intact_count() == 0) return out;
  out.offsets.assign(particles + 1, 0);
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (!bonds.intact[k]) continue;
    ++out.offsets[bonds.a[k] + 1];
    ++out.offsets[bonds.b[k] + 1];
  }
  for (std::size_t i = 0; i < particles; ++i) out.offsets[i + 1] += out.offsets[i];
  out.partners.resize(out.offsets[particles]);
  std::vector<std::uint32_t> next(out.offsets.begin(), out.offsets.end() - 1);
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (!bonds.intact[k]) continue;
    out.partners[next[bonds.a[k]]++] = bonds.b[k];
    out.partners[next[bonds.b[k]]++] = bonds.a[k];
  }
  for (std::size_t i = 0; i < particles; ++i) {
    std::sort(out.partners.begin() + out.offsets[i], out.partners.begin() + out.offsets[i + 1]);
  }
  return out;
}

namespace {

// The uncorrected shares: the fill lattice's cell for an interior sphere, the rest over the surface.
std::vector<double> voronoi_like_volumes(const std::vector<double>& radii, const std::vector<bool>& interior,
                                         double body_volume) {
  const double lattice_cell = 4.0 * std::sqrt(2.0);  // FCC of spacing 2 r: 4 sqrt(2) r^3 a point
  double interior_volume = 0.0;
  std::size_t surface = 0;
  for (std::size_t i = 0; i < radii.size(); ++i) {
    if (interior[i]) interior_volume += lattice_cell * radii[i] * radii[i] * radii[i];
    else ++surface;
  }
  // A thin body whose lattice claims more than its volume: the surface spheres keep the smallest share
  // that still makes sense, a sphere's own volume, and the correction below restores the total.
  double surface_share = surface ? (body_volume - interior_volume) / static_cast<double>(surface) : 0.0;
  std::vector<double> volumes(radii.size());
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double own = 4.0 / 3.0 * kPi * radii[i] * radii[i] * radii[i];
    volumes[i] = interior[i] ? lattice_cell * radii[i] * radii[i] * radii[i] : std::max(surface_share, own);
  }
  return volumes;
}

}  // namespace

std::vector<double> sphere_masses(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
                                  const std::vector<bool>& interior, const BodyMassShare& body) {
  const std::size_t n = centres.size();
  if (n == 0 || radii.size() != n || interior.size() != n) {
    throw std::invalid_argument("sphere_masses: needs spheres, each with a radius and an interior flag");
  }
  const std::vector<double> volumes = voronoi_like_volumes(radii, interior, body.volume);
  double total = 0.0;
  for (double v : volumes) total += v;
  std::vector<double> share(n);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    share[i] = body.mass * volumes[i] / total;
    centre += share[i] * centres[i];
  }
  centre /= body.mass;
  // m_i = s_i (1 + g . (x_i - x_s)) keeps the total (the weighted deviations add to zero) and moves
  // the centre by C g / M, C the shares' second moment about their centre.
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = centres[i] - centre;
    second_moment += share[i] * d * d.transpose();
  }
  const Eigen::Vector3d needed = body.mass * (body.centre_of_mass - centre);
  const Eigen::Vector3d g = second_moment.completeOrthogonalDecomposition().solve(needed);
  const double scale = std::max(1.0, centre.norm() + body.centre_of_mass.norm());
  if ((second_moment * g - needed).norm() > 1e-9 * body.mass * scale) {
    throw std::invalid_argument("the spheres lie in a plane or on a line that the body's centre of mass is off");
  }
  std::vector<double> masses(n);
  for (std::size_t i = 0; i < n; ++i) {
    masses[i] = share[i] * (1.0 + g.dot(centres[i] - centre));
    if (!(masses[i] > 0.0)) {
      throw std::invalid_argument("the spheres do not fill the body: keeping its centre of mass would make sphere " +
                                  std::to_string(i) + "'s mass non-positive");
    }
  }
  return masses;
}

double bond_time_step(const BondSet& bonds, const std::vector<double>& masses, const std::vector<double>& radii,
                      const BondMaterial& material) {
  std::vector<double> translational(masses.size(), 0.0), rotational(masses.size(), 0.0);
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    const std::uint32_t a = bonds.a[k], b = bonds.b[k];
    const BondGeometry<double> g = bond_geometry(radii[a], radii[b], material);
    const double stiffest = std::max(g.normal_stiffness, g.shear_stiffness);
    const double force = stiffest * g.area;  // N/m
    const double moment = std::max(g.normal_stiffness * g.bending_inertia, g.shear_stiffness * g.polar_inertia);
    for (const std::uint32_t s : {a, b}) {
      translational[s] += force;
      rotational[s] += moment + force * radii[s] * radii[s];  // the shear force acts at about r
    }
  }
  double step = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < masses.size(); ++s) {
    if (translational[s] <= 0.0) continue;
    const double inertia = 0.4 * masses[s] * radii[s] * radii[s];
    const double omega = std::sqrt(std::max(2.0 * translational[s] / masses[s], 2.0 * rotational[s] / inertia));
    step = std::min(step, kPi / (20.0 * omega));
  }
  return step;
}

}  // namespace ts::sim
