// The parallel bond (Potyondy & Cundall 2004), line for line the GLSL twin of sim/bond_model.h
// (turn_onto_plane, advance_bond, bond_stresses, bond_interaction), so the GPU and the CPU reference
// agree to rounding. The arithmetic is in `creal` (sim/precision.glsl) like the contact law's; the
// carried loads are state and stay in `real` (double in the double pipelines), so the increments
// of a long run add up in the state's precision. Sign conventions are bond_model.h's: n points from
// sphere b to sphere a, forces and moments are those on a.
#ifndef TETRASAND_SIM_BOND_GLSL
#define TETRASAND_SIM_BOND_GLSL
#include "sim/precision.glsl"

// One bond's geometry and strengths (TS_SIM_BOND_PARAMS), in creal.
struct BondParams {
  creal area, bending_inertia, polar_inertia, radius;  // m^2, m^4, m^4, m
  creal normal_stiffness, shear_stiffness;             // Pa/m
  creal tensile_strength, shear_strength;              // Pa
};

// What a bond carries (TS_SIM_BOND_STATE), in real.
struct BondCarried {
  real normal_force;    // N, > 0 compression
  real3 shear_force;    // N
  real twisting_moment;  // N m
  real3 bending_moment;  // N m
};

// Keeps a stored in-plane vector in the plane normal to n, with its length (the bond frame turns with
// the pair).
real3 bond_turn_onto_plane(real3 n, real3 v) {
  real length_before = length(v);
  v -= dot(v, n) * n;
  real projected = length(v);
  return projected > 0.0 ? v * (length_before / projected) : v;
}

// Advances the carried loads over dt by the relative motion at the bond's centre (v_rel, m/s) and the
// relative spin w_rel = w_a - w_b (rad/s).
void bond_advance(creal3 n, creal3 v_rel, creal3 w_rel, BondParams g, creal dt, inout BondCarried s) {
  real3 n_state = real3(n);
  s.shear_force = bond_turn_onto_plane(n_state, s.shear_force);
  s.bending_moment = bond_turn_onto_plane(n_state, s.bending_moment);
  creal v_n = dot(v_rel, n);
  creal3 v_s = v_rel - v_n * n;
  creal w_n = dot(w_rel, n);
  creal3 w_b = w_rel - w_n * n;
  s.normal_force -= real(g.normal_stiffness * g.area * v_n * dt);
  s.shear_force -= real3(g.shear_stiffness * g.area * dt * v_s);
  s.twisting_moment -= real(g.shear_stiffness * g.polar_inertia * w_n * dt);
  s.bending_moment -= real3(g.normal_stiffness * g.bending_inertia * dt * w_b);
}

// True when the largest tensile or shear stress on the bond's rim passes its strength.
bool bond_breaks(BondCarried s, BondParams g) {
  creal tensile = -creal(s.normal_force) / g.area + creal(length(s.bending_moment)) * g.radius / g.bending_inertia;
  creal shear = creal(length(s.shear_force)) / g.area + abs(creal(s.twisting_moment)) * g.radius / g.polar_inertia;
  return tensile > g.tensile_strength || shear > g.shear_strength;
}

// One bond in one step (bond_interaction): d = p_a - p_b (m, differenced in `real`), the sphere
// centres' relative velocity v_ab = v_a - v_b (m/s), the spins w (rad/s) and radii r (m). Advances
// the loads and checks the strengths; out: the force and moment on a and the arms from a's and b's
// centres to the bond's centre (all zero, and the loads cleared, when it broke or has no direction).
// Returns true when the bond broke in this step.
bool bond_interaction(creal3 d, creal3 v_ab, creal3 w_a, creal r_a, creal3 w_b, creal r_b, BondParams g, creal dt,
                      inout BondCarried s, out creal3 force, out creal3 moment, out creal3 arm_a, out creal3 arm_b) {
  force = creal3(0.0);
  moment = creal3(0.0);
  arm_a = creal3(0.0);
  arm_b = creal3(0.0);
  creal distance = length(d);
  if (!(distance > 0.0)) return false;  // coincident centres: no direction to carry a load along
  creal3 n = d / distance;
  // The bond's centre is the middle of the gap (or overlap) between the surfaces: from b, n times
  // (distance + r_b - r_a) / 2; from a, minus n times (distance + r_a - r_b) / 2.
  arm_a = -n * (0.5 * (distance + r_a - r_b));
  arm_b = n * (0.5 * (distance + r_b - r_a));
  creal3 v_rel = v_ab + cross(w_a, arm_a) - cross(w_b, arm_b);
  bond_advance(n, v_rel, w_a - w_b, g, dt, s);
  if (bond_breaks(s, g)) {
    s.normal_force = 0.0;
    s.shear_force = real3(0.0);
    s.twisting_moment = 0.0;
    s.bending_moment = real3(0.0);
    arm_a = creal3(0.0);
    arm_b = creal3(0.0);
    return true;
  }
  force = creal(s.normal_force) * n + creal3(s.shear_force);
  moment = creal(s.twisting_moment) * n + creal3(s.bending_moment);
  return false;
}
#endif
