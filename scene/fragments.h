#pragma once
// The fragments of a scene's breakable props (issue 48): the groups of spheres their intact bonds still
// join, found with a union-find over the bonds. A sphere with no intact bond is a fragment of one; a
// bond that binds a sphere to another prop's rigid body (bind_to) joins no fragment.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "scene/scene_world.h"
#include "sim/world.h"

namespace ts::scene {

struct Fragments {
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  // Per particle of the world: the fragment's lowest particle index (a stable label), or kNone for a
  // particle of no breakable prop.
  std::vector<std::uint32_t> label;
  std::size_t count = 0;       // fragments over all breakable props
  double largest_mass = 0;     // kg, of the heaviest fragment
  // Every fragment, heaviest first (equal masses by label): the fragment mass distribution.
  struct Piece {
    std::uint32_t label = 0;    // its lowest particle index
    std::uint32_t spheres = 0;
    double mass = 0;            // kg
  };
  std::vector<Piece> pieces;
};

// fragments.csv: one row per fragment (label, spheres, mass_kg), heaviest first.
std::string fragments_csv(const Fragments& fragments);

// `ranges`: each prop's bodies (prop_body_ranges); only the breakable ones' spheres are counted.
Fragments find_fragments(const World& world, const std::vector<BodyRange>& ranges);

}  // namespace ts::scene
