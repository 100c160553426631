#pragma once
// Parallel bonds between spheres: the law of breakable props (Potyondy & Cundall 2004, "A bonded-particle
// model for rock"; the parallel bond of PFC, LIGGGHTS' bond models and LAMMPS' BPM bpm/rotational in its
// linear form). docs/validation.md "Bonded particles" states the model and its criteria.
//
// A bond is a short elastic cylinder glued between two spheres. It resists stretching, shearing, twisting
// and bending with forces and moments that grow with the relative motion of the spheres (incremental,
// so a bond made between touching or overlapping spheres is at rest in the pose it was made in), and it
// breaks for good once the largest stress on its rim passes its strength. Like contact_model.h the law is
// a template over the scalar so the CPU reference and a float build share one definition, and it sticks
// to what GLSL has.
//
// Sign conventions are contact_model.h's: n points from sphere b to sphere a, forces and moments are the
// ones on sphere a (b gets the negated force and moment), applied at one point for both spheres so every
// bond conserves linear and angular momentum exactly.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>

#include "sim/contact_model.h"

namespace ts::sim {

struct BondMaterial {
  double youngs_modulus = 1.0e8;    // E of the bond cement, Pa: normal stiffness per area k_n = E / (r_a + r_b)
  double stiffness_ratio = 2.5;     // k_n / k_s, dimensionless, > 0 (PFC's default for rock is 2.5)
  double radius_factor = 1.0;       // lambda: bond radius = lambda min(r_a, r_b), in (0, 1]
  double tensile_strength = 1.0e6;  // sigma_c, Pa, > 0
  double shear_strength = 1.0e6;    // tau_c, Pa, > 0
  // Relative standard deviation of each bond's two strengths (0: every bond alike). Each bond draws its
  // factor from a normal distribution seeded by the scene's seed and the bond's spheres, floored at
  // kMinStrengthFactor so no bond is born broken.
  double strength_spread = 0.0;
  // Spheres whose centres are closer than bond_distance (r_a + r_b) are bonded, >= 1: the lattice of
  // `sample --fill` puts neighbours at exactly r_a + r_b, the surface spheres a little farther.
  double bond_distance = 1.2;

  bool operator==(const BondMaterial&) const = default;
};

// The smallest strength factor a bond may draw (BondMaterial::strength_spread).
inline constexpr double kMinStrengthFactor = 0.05;

// Empty when the material is usable, else its first problem ("tensile_strength: must be > 0").
std::string validate(const BondMaterial& material);

// The cross-section and stiffnesses of one bond.
template <typename Real>
struct BondGeometry {
  Real radius = 0;            // R = lambda min(r_a, r_b), m
  Real area = 0;              // A = pi R^2, m^2
  Real bending_inertia = 0;   // I = pi R^4 / 4, m^4
  Real polar_inertia = 0;     // J = pi R^4 / 2, m^4
  Real normal_stiffness = 0;  // k_n, Pa/m (force per area per metre of stretch)
  Real shear_stiffness = 0;   // k_s = k_n / stiffness_ratio, Pa/m
};

template <typename Real>
BondGeometry<Real> bond_geometry(Real radius_a, Real radius_b, const BondMaterial& material) {
  BondGeometry<Real> g;
  g.radius = Real(material.radius_factor) * std::min(radius_a, radius_b);
  const Real pi = Real(3.14159265358979323846);
  g.area = pi * g.radius * g.radius;
  g.bending_inertia = Real(0.25) * pi * g.radius * g.radius * g.radius * g.radius;
  g.polar_inertia = Real(2) * g.bending_inertia;
  g.normal_stiffness = Real(material.youngs_modulus) / (radius_a + radius_b);
  g.shear_stiffness = g.normal_stiffness / Real(material.stiffness_ratio);
  return g;
}

// What a bond carries, on sphere a. The shear force and the bending moment lie in the plane normal to
// n; the normal force and the twisting moment are along n.
template <typename Real>
struct BondState {
  Real normal_force = 0;                                 // N; > 0 pushes a away from b (compression)
  Vec3<Real> shear_force = Vec3<Real>::Zero();           // N
  Real twisting_moment = 0;                              // N m, about n
  Vec3<Real> bending_moment = Vec3<Real>::Zero();        // N m
};

// The largest stresses on the bond's rim (Pa): tension is positive (a compressed bond has a negative
// normal part), shear never negative.
template <typename Real>
struct BondStresses {
  Real tensile = 0;
  Real shear = 0;
};

template <typename Real>
BondStresses<Real> bond_stresses(const BondState<Real>& s, const BondGeometry<Real>& g) {
  return {-s.normal_force / g.area + s.bending_moment.norm() * g.radius / g.bending_inertia,
          s.shear_force.norm() / g.area + std::abs(s.twisting_moment) * g.radius / g.polar_inertia};
}

// Elastic energy the bond holds (J): each of its four springs' load^2 / (2 stiffness).
template <typename Real>
Real bond_energy(const BondState<Real>& s, const BondGeometry<Real>& g) {
  return s.normal_force * s.normal_force / (Real(2) * g.normal_stiffness * g.area) +
         s.shear_force.squaredNorm() / (Real(2) * g.shear_stiffness * g.area) +
         s.twisting_moment * s.twisting_moment / (Real(2) * g.shear_stiffness * g.polar_inertia) +
         s.bending_moment.squaredNorm() / (Real(2) * g.normal_stiffness * g.bending_inertia);
}

// Keeps a stored in-plane vector in the plane normal to the current n, with its length: the bond
// frame turns with the pair, and the load it carries turns with it (as the tangential spring does).
template <typename Real>
void turn_onto_plane(const Vec3<Real>& n, Vec3<Real>& v) {
  const Real length = v.norm();
  v -= v.dot(n) * n;
  const Real projected = v.norm();
  if (projected > Real(0)) v *= length / projected;
}

// Advances a bond over dt by the relative motion of sphere a against b at the bond's centre: v_rel, the
// relative velocity of that point (m/s), and w_rel = w_a - w_b (rad/s).
template <typename Real>
void advance_bond(const Vec3<Real>& n, const Vec3<Real>& v_rel, const Vec3<Real>& w_rel, const BondGeometry<Real>& g,
                  Real dt, BondState<Real>& s) {
  turn_onto_plane(n, s.shear_force);
  turn_onto_plane(n, s.bending_moment);
  const Real v_n = v_rel.dot(n);
  const Vec3<Real> v_s = v_rel - v_n * n;
  const Real w_n = w_rel.dot(n);
  const Vec3<Real> w_b = w_rel - w_n * n;
  s.normal_force -= g.normal_stiffness * g.area * v_n * dt;
  s.shear_force -= g.shear_stiffness * g.area * dt * v_s;
  s.twisting_moment -= g.shear_stiffness * g.polar_inertia * w_n * dt;
  s.bending_moment -= g.normal_stiffness * g.bending_inertia * dt * w_b;
}

// One bonded pair in one step: what sphere a gets (sphere b: -force, and -moment plus its own arm's
// torque), where it acts, and whether the bond broke in this step.
template <typename Real>
struct BondLoad {
  Vec3<Real> force = Vec3<Real>::Zero();   // N, on a
  Vec3<Real> moment = Vec3<Real>::Zero();  // N m, on a, besides the force's torque about a's centre
  Vec3<Real> arm_a = Vec3<Real>::Zero();   // m, from a's centre to the bond's centre
  Vec3<Real> arm_b = Vec3<Real>::Zero();   // m, from b's centre to the bond's centre
  bool broke = false;
};

// The bond between spheres a and b: centres p (m), the velocities of their bodies' centres v (m/s) and
// angular velocities w (rad/s) (spheres of one rigid body share w; v is then the sphere's own), radii r.
// The bond's centre is the middle of the gap (or overlap) between the two surfaces. Advances the state,
// then checks the strengths (Pa) against the new stresses: a bond that breaks carries nothing from
// this step on.
template <typename Real>
BondLoad<Real> bond_interaction(const Vec3<Real>& p_a, const Vec3<Real>& v_a, const Vec3<Real>& w_a, Real r_a,
                                const Vec3<Real>& p_b, const Vec3<Real>& v_b, const Vec3<Real>& w_b, Real r_b,
                                const BondGeometry<Real>& g, Real tensile_strength, Real shear_strength, Real dt,
                                BondState<Real>& s) {
  BondLoad<Real> load;
  const Vec3<Real> d = p_a - p_b;
  const Real distance = d.norm();
  if (!(distance > Real(0))) return load;  // coincident centres: no direction to carry a load along
  const Vec3<Real> n = d / distance;
  const Vec3<Real> centre = p_b + n * (Real(0.5) * (distance + r_b - r_a));
  load.arm_a = centre - p_a;
  load.arm_b = centre - p_b;
  const Vec3<Real> v_rel = (v_a + w_a.cross(load.arm_a)) - (v_b + w_b.cross(load.arm_b));
  advance_bond(n, v_rel, Vec3<Real>(w_a - w_b), g, dt, s);
  const BondStresses<Real> stress = bond_stresses(s, g);
  if (stress.tensile > tensile_strength || stress.shear > shear_strength) {
    load.broke = true;
    s = BondState<Real>{};
    return load;
  }
  load.force = s.normal_force * n + s.shear_force;
  load.moment = s.twisting_moment * n + s.bending_moment;
  return load;
}

}  // namespace ts::sim
