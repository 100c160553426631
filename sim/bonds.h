#pragma once
// The bonds of a breakable prop: which spheres of a `sample --fill` body are glued to which, each bond's
// strengths, and each sphere's mass once the body is taken apart into spheres (issue 48; the law is
// sim/bond_model.h, the model and its criteria docs/validation.md "Bonded particles").
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "sim/bond_model.h"

namespace ts::sim {

// Every bond of a scene, a structure of arrays in (a, b) order with a < b: sphere indices, strengths and
// the carried loads. A broken bond stays in the arrays (intact = 0) so indices and outputs keep their
// meaning; its loads are zero.
struct BondSet {
  std::vector<std::uint32_t> a, b;
  std::vector<std::uint16_t> material;   // index into World::bond_materials
  std::vector<double> tensile_strength;  // Pa, this bond's (BondMaterial::strength_spread)
  std::vector<double> shear_strength;    // Pa
  std::vector<std::uint8_t> intact;      // 1 until the bond breaks
  // m, r_a + r_b - |x_a - x_b| when the bond was made, floored at 0: how far the pair overlapped at
  // rest. Once the bond breaks the contact law takes only the overlap beyond it, so a pair bonded
  // overlapping (a sampled surface shell's neighbours) is not pushed apart by its own rest pose.
  std::vector<double> rest_overlap;
  std::vector<BondState<double>> state;

  std::size_t size() const { return a.size(); }
  std::size_t intact_count() const;
};

// Bonds every pair of spheres whose centres are closer than material.bond_distance (r_a + r_b), in
// ascending (a, b) order, found through a hashed grid (so linear in the sphere count). Strengths are
// the material's times a factor 1 + strength_spread z, z a standard normal drawn from (seed, a, b) alone
// (the same bonds get the same strengths whatever else the scene holds), floored at kMinStrengthFactor.
BondSet build_bonds(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
                    const BondMaterial& material, std::uint64_t seed);

// Appends `more` to `bonds` with its sphere indices moved by `first_particle` and its material set to
// `material` (a prop's bonds, built on its own spheres, into the world's).
void append_bonds(BondSet& bonds, const BondSet& more, std::uint32_t first_particle, std::uint16_t material);

// Each particle's intact bond partners, ascending (CSR over particle ids): the pairs the contact law
// leaves to their bond. Empty (no offsets) when no bond is intact.
struct BondedPartners {
  std::vector<std::uint32_t> offsets, partners;

  bool empty() const { return offsets.empty(); }
  bool bonded(std::uint32_t i, std::uint32_t j) const;
};
BondedPartners bonded_partners(const BondSet& bonds, std::size_t particles);

// Each particle's bond partners whose spheres overlapped when bonded, with that rest overlap (CSR over
// particle ids, partners ascending; intact or broken alike: the lists keep intact pairs from the
// contact law anyway). Empty (no offsets) when no bond has a rest overlap.
struct RestOverlaps {
  std::vector<std::uint32_t> offsets, partners;
  std::vector<double> overlap;  // m

  bool empty() const { return offsets.empty(); }
  // m: the rest overlap of the bond joining i and j, 0 when there is none.
  double of(std::uint32_t i, std::uint32_t j) const;
};
RestOverlaps rest_overlaps(const BondSet& bonds, std::size_t particles);

// The mass properties a body hands to its spheres.
struct BodyMassShare {
  double mass = 0;                                       // kg, the closed mesh's
  double volume = 0;                                     // m^3, the closed mesh's
  Eigen::Vector3d centre_of_mass = Eigen::Vector3d::Zero();  // m, in the same frame as the centres
};

// Each sphere's mass: its Voronoi-like share of the body (the lattice cell 4 sqrt(2) r^3 of an
// interior sphere, the rest of the volume split evenly over the surface spheres), then corrected by a
// term linear in position, m_i = s_i (1 + g . (x_i - x_s)), so that the masses add up to the body's
// mass and their centre is the body's centre of mass, both to round-off. Throws std::invalid_argument
// when that is impossible (all spheres in a plane or line the centre of mass is off, or a correction
// that would make a mass non-positive: a body whose spheres do not fill it).
std::vector<double> sphere_masses(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
                                  const std::vector<bool>& interior, const BodyMassShare& body);

// The bonds' share of the time-step bound (s), built like the contacts' t_c / 20: a twentieth of the
// half period pi / omega of the stiffest bonded motion. For each sphere omega^2 = 2 k / m over its bonds'
// summed translational stiffness k (the sphere and its neighbours moving against each other; exact for
// a pair of equal spheres) and 2 k_rot / I over their rotational stiffness (bending or twisting plus the
// shear force's arm), I = 2/5 m r^2; the smallest step over the spheres, so omega dt <= pi / 20 and
// symplectic Euler is far from its limit omega dt = 2. +inf without bonds.
double bond_time_step(const BondSet& bonds, const std::vector<double>& masses, const std::vector<double>& radii,
                      const BondMaterial& material);

}  // namespace ts::sim
