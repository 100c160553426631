#pragma once
// Scenes shared by the benchmarks (defined once, like Box2D's shared/ folder).
#include <cstdint>

#include "sim/world.h"

namespace ts::bench {

// `grains` tetrahedral grains (r = 1 mm, edge 2 mm, E = 10 MPa), randomly oriented on a lattice spaced
// 1.1 bounding diameters (no initial overlap), in a box with a floor and four smooth side walls,
// falling under gravity: the workload of a pour that is settling.
sim::World settling_box(std::uint32_t grains, std::uint64_t seed);

}  // namespace ts::bench
