#include "scene/fragments.h"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

namespace ts::scene {
namespace {

// Union-find with path halving; the smaller index becomes the root, so a label is the lowest particle.
std::uint32_t root_of(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

}  // namespace

Fragments find_fragments(const World& world, const std::vector<BodyRange>& ranges) {
  const std::size_t n = world.particles.size();
  std::vector<std::uint8_t> breakable(n, 0);
  for (const BodyRange& r : ranges) {
    if (!r.breakable) continue;
    for (std::uint32_t b = r.first; b < r.first + r.count; ++b) {
      const std::uint32_t first = world.bodies.first_particle[b];
      std::fill_n(breakable.begin() + first, world.bodies.particle_count[b], std::uint8_t{1});
    }
  }
  std::vector<std::uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), std::uint32_t{0});
  const sim::BondSet& bonds = world.bonds;
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (!bonds.intact[k] || !breakable[bonds.a[k]] || !breakable[bonds.b[k]]) continue;
    const std::uint32_t a = root_of(parent, bonds.a[k]), b = root_of(parent, bonds.b[k]);
    parent[std::max(a, b)] = std::min(a, b);
  }
  Fragments f;
  f.label.assign(n, Fragments::kNone);
  std::vector<double> mass(n, 0.0);  // kg, by root
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!breakable[i]) continue;
    const std::uint32_t root = root_of(parent, i);
    f.label[i] = root;
    f.count += root == i ? 1 : 0;
    mass[root] += 1.0 / world.bodies.inverse_mass[world.particles.body[i]];
  }
  f.largest_mass = n == 0 ? 0.0 : *std::max_element(mass.begin(), mass.end());
  std::vector<std::uint32_t> spheres(n, 0);
  for (std::uint32_t i = 0; i < n; ++i)
    if (f.label[i] != Fragments::kNone) ++spheres[f.label[i]];
  for (std::uint32_t i = 0; i < n; ++i)
    if (f.label[i] == i) f.pieces.push_back({i, spheres[i], mass[i]});
  std::stable_sort(f.pieces.begin(), f.pieces.end(),
                   [](const Fragments::Piece& a, const Fragments::Piece& b) { return a.mass > b.mass; });
  return f;
}

std::string fragments_csv(const Fragments& fragments) {
  std::string csv = "label,spheres,mass_kg\n";
  for (const Fragments::Piece& p : fragments.pieces) csv += fmt::format("{},{},{:.9g}\n", p.label, p.spheres, p.mass);
  return csv;
}

}  // namespace ts::scene
