#include "bench/bench_scenes.h"

#include <cmath>
#include <random>

#include "sim/grain.h"

namespace ts::bench {

sim::World settling_box(std::uint32_t grains, std::uint64_t seed) {
  sim::World world;
  sim::Material sand;
  sand.youngs_modulus = 1e7;
  world.materials = {sand};
  const sim::GrainShape grain = sim::make_tetrahedral_grain(0.001, 0.002, sand.density);
  const double spacing = 2.2 * grain.bounding_radius;  // m: lattice spacing, no initial overlap
  const auto side = static_cast<std::uint32_t>(std::ceil(std::sqrt(grains / 4.0)));  // a column 4x as tall as wide
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::uint32_t n = 0; n < grains; ++n) {
    const Eigen::Vector3d position(spacing * (0.5 + n % side), spacing * (0.5 + (n / side) % side),
                                   spacing * (0.5 + n / (side * side)));
    const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    sim::add_grain(world, grain, 0, position, q, 0.05 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  const double width = spacing * side;
  world.walls.planes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0},
                        {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 0},
                        {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 0},
                        {Eigen::Vector3d(width, 0, 0), -Eigen::Vector3d::UnitX(), 0},
                        {Eigen::Vector3d(0, width, 0), -Eigen::Vector3d::UnitY(), 0}};
  return world;
}

}  // namespace ts::bench
