#pragma once
// The lattice an emitter's grains start on: sites spaced 2.2 bounding radii apart (so no two grains
// overlap whatever their orientation, notes/peers.md), jittered by at most 2 % of the spacing.
#include <Eigen/Core>

#include <random>
#include <vector>

namespace ts::scene {

// Lattice sites of one emitter region: each is drawn, jittered and stored (24 bytes) before the
// first grain is placed, 3 GiB at the limit.
inline constexpr double kMaxLatticeSites = 134217728.0;  // 2^27

// The lattice's spacing (m) for grains of bounding radius `bound` (m).
double lattice_spacing(double bound);

// How many sites a box holds, in double so a huge box does not overflow; 0 when the box is smaller
// than one grain.
double lattice_site_count(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double bound);

// The jittered sites (m) in a box, drawn with `rng`. Throws ts::InputError past kMaxLatticeSites.
std::vector<Eigen::Vector3d> grain_sites_in_box(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double bound,
                                                std::mt19937_64& rng);

}  // namespace ts::scene
