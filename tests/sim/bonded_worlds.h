#pragma once
// Bonded worlds shared by the bond tests of both steppers (cpu_bonds_test.cpp, gpu_bonds_test.cpp).
#include <cmath>
#include <vector>

#include "sim/bonds.h"
#include "sim/stepper.h"
#include "sim/world.h"

namespace ts::sim::bonded {

using V = Eigen::Vector3d;
inline constexpr double kRadius = 1e-3;  // m

inline BondMaterial cement(double strength = 1e9) {
  BondMaterial m;
  m.youngs_modulus = 1e8;
  m.tensile_strength = strength;
  m.shear_strength = strength;
  return m;
}

// An FCC block of n^3 cells of touching spheres, each sphere its own dynamic body, all bonded.
inline World bonded_block(int n, const BondMaterial& bond, const V& centre = V::Zero()) {
  World w;
  w.materials.push_back(Material{});
  w.gravity = V::Zero();
  const double edge = 2.0 * std::sqrt(2.0) * kRadius;
  const V basis[4] = {V(0, 0, 0), V(0.5, 0.5, 0), V(0.5, 0, 0.5), V(0, 0.5, 0.5)};
  std::vector<V> centres;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (const V& b : basis) centres.push_back(edge * (V(x, y, z) + b));
  V mean = V::Zero();
  for (const V& c : centres) mean += c;
  mean /= static_cast<double>(centres.size());
  for (V& c : centres) c += centre - mean;  // the block's centre of mass at `centre`
  const double mass = w.materials[0].density * 4.0 * std::sqrt(2.0) * std::pow(kRadius, 3);  // a lattice cell's
  for (const V& c : centres) {
    BodyDesc d;
    d.position = c;
    d.inverse_mass = 1.0 / mass;
    d.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * mass * kRadius * kRadius);
    add_body(w, d, {V::Zero()}, {kRadius}, 0);
  }
  w.bonds = build_bonds(centres, std::vector<double>(centres.size(), kRadius), bond, 11);
  w.bond_materials = {bond};
  return w;
}

inline double bond_step(const World& w) {
  std::vector<double> masses, radii;
  for (std::size_t k = 0; k < w.bodies.size(); ++k) masses.push_back(1.0 / w.bodies.inverse_mass[k]);
  radii = w.particles.radius;
  return bond_time_step(w.bonds, masses, radii, w.bond_materials[0]);
}

inline StepSettings symplectic(double dt) {
  StepSettings s;
  s.dt = dt;
  s.integrator = Integrator::SemiImplicitEuler;
  s.design_speed = 1.0;
  return s;
}

// A static floor of 13 x 13 touching spheres of kRadius centred on the origin at z = 0, one body.
inline void add_sphere_floor(World& w) {
  std::vector<V> floor;
  for (int i = -6; i <= 6; ++i)
    for (int j = -6; j <= 6; ++j) floor.emplace_back(2 * kRadius * i, 2 * kRadius * j, 0.0);
  BodyDesc ground;
  ground.motion = MotionType::Static;
  add_body(w, ground, floor, std::vector<double>(floor.size(), kRadius), 0);
}

// Two touching spheres of `mass` (kg) each, pressed together and sliding past each other, bonded with a
// shear strength of 1 kPa: the bond breaks in shear within a few hundred steps of 1e-8 s.
inline World sliding_pair_bonded_weakly_in_shear(double mass) {
  World two;
  two.materials = {Material{}};
  two.gravity = V::Zero();
  for (double x : {-kRadius, kRadius}) {
    BodyDesc d;
    d.position = V(x, 0, 0);
    d.linear_velocity = V(x > 0 ? -0.01 : 0.01, x > 0 ? 0.05 : -0.05, 0);
    d.inverse_mass = 1.0 / mass;
    d.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * mass * kRadius * kRadius);
    add_body(two, d, {V::Zero()}, {kRadius}, 0);
  }
  BondMaterial weak_shear = cement();
  weak_shear.shear_strength = 1e3;
  two.bonds = build_bonds({two.bodies.position[0], two.bodies.position[1]}, {kRadius, kRadius}, weak_shear, 1);
  two.bond_materials = {weak_shear};
  return two;
}

// Two spheres bonded while they overlap by a tenth of a radius (their rest overlap), moving apart at
// `speed` each (m/s), with a tensile strength low enough that the bond breaks on the way.
inline World overlapping_pair(double speed) {
  World w;
  w.materials = {Material{}};
  w.gravity = V::Zero();
  const double mass = w.materials[0].density * 4.0 / 3.0 * 3.14159265358979323846 * std::pow(kRadius, 3);
  for (double side : {-1.0, 1.0}) {
    BodyDesc d;
    d.position = V(side * 0.95 * kRadius, 0, 0);
    d.linear_velocity = V(side * speed, 0, 0);
    d.inverse_mass = 1.0 / mass;
    d.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * mass * kRadius * kRadius);
    add_body(w, d, {V::Zero()}, {kRadius}, 0);
  }
  BondMaterial weak = cement(1e4);
  w.bonds = build_bonds({w.bodies.position[0], w.bodies.position[1]}, {kRadius, kRadius}, weak, 1);
  w.bond_materials = {weak};
  return w;
}

}  // namespace ts::sim::bonded
