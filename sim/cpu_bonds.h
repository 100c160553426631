#pragma once
// The bonds' stage of the CPU reference (issue 48): each intact bond of the world advanced over the step,
// its load added to the two spheres it joins, and those whose stress passes their strength broken.
// Bonds are visited in their (a, b) order and their loads summed in that order, so a run is
// deterministic and a resumed one goes on bit for bit (the bonds' state is in the checkpoint).
#include <Eigen/Core>

#include <cstddef>
#include <vector>

#include "sim/bonds.h"
#include "sim/world.h"

namespace ts::sim {

struct BondStep {
  double energy = 0;     // J, held by the intact bonds at the step's start (before they advance)
  std::size_t broke = 0;  // bonds broken in this step
};

// `positions`: every particle's world position (m) at the step's start; `force` and `torque` (N, N m
// about the particle's centre), world order, are added to. Broken bonds go on carrying nothing.
BondStep add_bond_loads(World& world, const std::vector<Eigen::Vector3d>& positions, double dt,
                        std::vector<Eigen::Vector3d>& force, std::vector<Eigen::Vector3d>& torque);

// J: what the intact bonds of `world` hold.
double bond_energy(const World& world);

}  // namespace ts::sim
