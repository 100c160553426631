#include "sim/cpu_bonds.h"

#include <tbb/parallel_for.h>

namespace ts::sim {
namespace {

BondGeometry<double> geometry_of(const World& world, std::size_t k) {
  const BondSet& bonds = world.bonds;
  return bond_geometry(world.particles.radius[bonds.a[k]], world.particles.radius[bonds.b[k]],
                       world.bond_materials[bonds.material[k]]);
}

// The velocity of particle i's centre (m/s): its body's, and the body's spin about the body's centre.
Eigen::Vector3d particle_velocity(const World& world, const std::vector<Eigen::Vector3d>& positions, std::uint32_t i) {
  const std::uint32_t body = world.particles.body[i];
  return world.bodies.linear_velocity[body] +
         world.bodies.angular_velocity[body].cross(positions[i] - world.bodies.position[body]);
}

}  // namespace

double bond_energy(const World& world) {
  double energy = 0.0;
  for (std::size_t k = 0; k < world.bonds.size(); ++k) {
    if (world.bonds.intact[k]) energy += bond_energy(world.bonds.state[k], geometry_of(world, k));
  }
  return energy;
}

BondStep add_bond_loads(World& world, const std::vector<Eigen::Vector3d>& positions, double dt,
                        std::vector<Eigen::Vector3d>& force, std::vector<Eigen::Vector3d>& torque) {
  BondSet& bonds = world.bonds;
  BondStep step;
  step.energy = bond_energy(world);
  // Each bond's load in parallel (a bond reads only its own state), then summed in bond order.
  std::vector<BondLoad<double>> loads(bonds.size());
  tbb::parallel_for(std::size_t{0}, bonds.size(), [&](std::size_t k) {
    if (!bonds.intact[k]) return;
    const std::uint32_t a = bonds.a[k], b = bonds.b[k];
    const Particles& p = world.particles;
    loads[k] = bond_interaction(positions[a], particle_velocity(world, positions, a),
                                world.bodies.angular_velocity[p.body[a]], p.radius[a], positions[b],
                                particle_velocity(world, positions, b), world.bodies.angular_velocity[p.body[b]],
                                p.radius[b], geometry_of(world, k), bonds.tensile_strength[k],
                                bonds.shear_strength[k], dt, bonds.state[k]);
  });
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (!bonds.intact[k]) continue;
    const BondLoad<double>& load = loads[k];
    if (load.broke) {
      bonds.intact[k] = 0;
      ++step.broke;
      continue;
    }
    const std::uint32_t a = bonds.a[k], b = bonds.b[k];
    force[a] += load.force;
    torque[a] += load.arm_a.cross(load.force) + load.moment;
    force[b] -= load.force;
    torque[b] += load.arm_b.cross(-load.force) - load.moment;
  }
  return step;
}

}  // namespace ts::sim
