#pragma once
// Sphere-sphere and sphere-wall contact forces (thesis ch. 3; docs in shared notes/formulas.md).
//
// The force functions are templates over the scalar type so the CPU reference (double) and a float
// build share one definition; the GPU kernels reimplement them line by line in GLSL, so the code
// below sticks to what GLSL has: dot, cross, length, sqrt, pow, min, max, no branches on data
// beyond "touching or not".
//
// Sign conventions: n points from particle 2 to particle 1 (from the wall into the free side), the
// returned force acts on particle 1 (particle 2 gets its negation), and its point of application is
// the middle of the overlap, `centre1 + arm1`, the same point for both partners so that angular
// momentum is conserved exactly by every pair.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <string>

namespace ts::sim {

struct Material {
  double youngs_modulus = 1.0e7;    // E, Pa (thesis uses 10-100 MPa after Bell et al.)
  double poisson_ratio = 0.3;       // nu, dimensionless, in [0, 0.5)
  double restitution = 0.65;        // e_n in (0, 1]: requested normal coefficient of restitution
  double friction = 0.5;            // mu, Coulomb cap of the tangential force, dimensionless
  // gamma_s, N s/m. The thesis's 10 (section 4.5) is in its rescaled units: for millimetre grains
  // (m ~ 4e-5 kg) an explicit step is only stable below m_t / gamma_s (see time_step.h), which
  // gamma_s = 10 would push under a microsecond.
  double tangential_damping = 0.1;
  double density = 2600.0;          // kg/m^3 (quartz)

  bool operator==(const Material&) const = default;
};

// Returns an empty string when the material is usable, else the first problem ("E: must be > 0").
std::string validate(const Material& material);

// How the normal force dissipates energy.
enum class NormalDamping {
  // Constant restitution (Tsuji et al. 1992; LAMMPS/LIGGGHTS hertz/material ... damping tsuji):
  // F_d = -2 sqrt(5/6) beta sqrt(S_n m*) delta_dot, S_n = 2 E* sqrt(R* delta). The restitution it
  // gives does not depend on the impact speed.
  Tsuji,
  // Thesis eq. 3.27: F_d = gamma_n delta^(1/2) delta_dot. Restitution falls with impact speed,
  // (1 - e) ~ v^(1/5) as measured by Kuwabara & Kono 1987.
  Thesis,
};

// Everything a contact between two materials needs, computed once per material pair (the GPU keeps
// a small table of these indexed by the two material ids).
struct PairCoefficients {
  double effective_modulus = 0;   // E*, Pa: 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2
  double friction = 0;            // mu, geometric mean of the two materials'
  double tangential_damping = 0;  // gamma_s, N s/m, geometric mean
  double restitution = 1;         // e_n, geometric mean
  // Dimensionless damping strength c of the scaled equation x'' = -x^(3/2) - c x^p x' (see
  // damping_strength_for_restitution): Tsuji p = 1/4 with c = -sqrt(5) beta; thesis p = 1/2.
  double damping_strength = 0;
  double thesis_reference_speed = 1;  // m/s: thesis form only, the speed at which e_n is exact
  // G*, Pa: 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2, G = E / (2 (1 + nu)); the tangential spring's
  // Mindlin stiffness k_t = 8 G* sqrt(R* delta) (only with TangentialModel::Spring).
  double effective_shear_modulus = 0;
};

// Mixing rules and damping calibration for one pair of materials. The damping strength is chosen so
// that a head-on impact with the normal force clamped at zero (no attraction) rebounds with exactly
// the mixed restitution: for Tsuji at every speed, for the thesis form at thesis_reference_speed.
// (LAMMPS's beta = ln e / sqrt(ln^2 e + pi^2) is exact only when the force may turn attractive at
// the end of the contact; clamped, e = 0.65 would come out as 0.675.)
PairCoefficients make_pair_coefficients(const Material& a, const Material& b, NormalDamping damping,
                                        double thesis_reference_speed = 1.0);

// The dimensionless damping strength c for which the clamped, scaled Hertz oscillator
//   x'' = -x^(3/2) - c x^p x',  x(0) = 0, x'(0) = 1, force clamped at >= 0
// rebounds with velocity -e. Every Hertz contact with damping ~ delta^p delta_dot maps onto this
// equation with delta = delta0 x, t = (delta0 / v) tau, delta0 = (m* v^2 / k_n)^(2/5).
// Solved by bisection on a fixed-step RK4 integration (deterministic, about a millisecond).
double damping_strength_for_restitution(double restitution, double exponent);

// The restitution and scaled contact duration (in units of delta0 / v) of that oscillator.
struct ScaledImpact {
  double restitution;
  double duration;
};
ScaledImpact scaled_hertz_impact(double damping_strength, double exponent);

template <typename Real>
using Vec3 = Eigen::Matrix<Real, 3, 1>;

// Pair coefficients in the kernel's precision.
template <typename Real>
struct ContactCoefficients {
  Real effective_modulus, friction, tangential_damping, damping_strength, thesis_reference_speed;
  NormalDamping damping;
  Real effective_shear_modulus = 0;  // Pa, tangential spring only
  static ContactCoefficients from(const PairCoefficients& p, NormalDamping d) {
    return {Real(p.effective_modulus), Real(p.friction), Real(p.tangential_damping), Real(p.damping_strength),
            Real(p.thesis_reference_speed), d, Real(p.effective_shear_modulus)};
  }
};

template <typename Real>
struct ContactForce {
  Vec3<Real> force = Vec3<Real>::Zero();  // N, on particle 1
  Vec3<Real> arm = Vec3<Real>::Zero();    // m, from particle 1's centre to the point of application
  Real overlap = 0;                       // m, as used in the force (after the overlap clamp)
  Real elastic_energy = 0;                // J, 2/5 k_n delta^(5/2) stored in the Hertz spring
  bool touching = false;
  bool overlap_clamped = false;
  // Against a wall: the raw overlap exceeds the particle's diameter, so the whole sphere is behind
  // the wall's surface: it has passed through (StepSettings::check_penetration).
  bool passed_through = false;
};

// Normal plus tangential force for a contact with normal n (towards body 1), overlap delta > 0,
// relative contact velocity v_c = v1 - v2 at the contact point, effective radius R* (m) and
// effective mass m* (kg). Hertz elastic part (eq. 3.19), damping per coefficients, no attraction,
// viscous tangential force capped by Coulomb (eq. 3.28), or with `spring` the spring form above
// (dt, s: the step that advances the spring).
// The static-friction alternative to eq. 3.28's purely viscous tangential force, which cannot hold a
// load at zero slip, so a heap creeps down its slope at the slip speed F_t / gamma_s (thesis figure
// 2.8). A spring per contact (Cundall & Strack 1979; LAMMPS's "tangential mindlin") stores the
// elastic tangential displacement `spring` (m, of particle 1 relative to 2): it is turned onto the
// current tangent plane keeping its length, advanced by the slip v_s dt, and the force
// -k_t spring - gamma_s v_s with k_t = 8 G* sqrt(R* delta) is capped at mu F_n; while sliding, the
// spring is cut back to what the capped force implies. Both partners of a pair keep their own
// spring; the arithmetic is antisymmetric term by term, so the two stay exact negatives.
template <typename Real>
Vec3<Real> spring_tangential_force(const Vec3<Real>& n, Real delta, const Vec3<Real>& v_c, Real effective_radius,
                                   Real normal_force, const ContactCoefficients<Real>& c, Real dt,
                                   Vec3<Real>& spring) {
  const Vec3<Real> v_s = v_c - v_c.dot(n) * n;  // m/s
  const Real length = spring.norm();
  spring -= spring.dot(n) * n;
  const Real projected = spring.norm();
  if (projected > Real(0)) spring *= length / projected;
  spring += v_s * dt;
  const Real k_t = Real(8) * c.effective_shear_modulus * std::sqrt(effective_radius * delta);  // N/m
  Vec3<Real> force = -k_t * spring - c.tangential_damping * v_s;
  const Real cap = c.friction * normal_force;
  const Real magnitude = force.norm();
  if (magnitude > cap) {
    force *= magnitude > Real(0) ? cap / magnitude : Real(0);
    spring = -(force + c.tangential_damping * v_s) / k_t;
  }
  return force;
}

template <typename Real>
Vec3<Real> hertz_contact_force(const Vec3<Real>& n, Real delta, const Vec3<Real>& v_c, Real effective_radius,
                               Real effective_mass, const ContactCoefficients<Real>& c, Real dt = Real(0),
                               Vec3<Real>* spring = nullptr) {
  const Real k_n = Real(4.0 / 3.0) * c.effective_modulus * std::sqrt(effective_radius);  // N/m^1.5
  const Real delta_dot = -v_c.dot(n);  // m/s, > 0 while approaching
  Real damping_force;                  // N, along n
  if (c.damping == NormalDamping::Tsuji) {
    // -2 sqrt(5/6) beta sqrt(S_n m*) delta_dot with beta = -c / sqrt(5): see PairCoefficients.
    const Real s_n = Real(2) * c.effective_modulus * std::sqrt(effective_radius * delta);  // N/m
    damping_force = Real(2.0 * std::sqrt(5.0 / 6.0) / std::sqrt(5.0)) * c.damping_strength *
                    std::sqrt(s_n * effective_mass) * delta_dot;
  } else {
    // gamma_n = c (m*^2 k_n^3 / v_ref)^(1/5) (N s / m^1.5) makes eq. 3.27 rebound with e_n at v_ref.
    const Real gamma_n = c.damping_strength *
                         std::pow(effective_mass * effective_mass * k_n * k_n * k_n / c.thesis_reference_speed,
                                  Real(0.2));
    damping_force = gamma_n * std::sqrt(delta) * delta_dot;
  }
  const Real normal_force = std::max(Real(0), k_n * delta * std::sqrt(delta) + damping_force);  // N
  if (spring) {
    return normal_force * n + spring_tangential_force(n, delta, v_c, effective_radius, normal_force, c, dt, *spring);
  }

  const Vec3<Real> v_s = v_c - v_c.dot(n) * n;  // m/s, tangential slip
  const Real slip = v_s.norm();
  Vec3<Real> tangential = Vec3<Real>::Zero();
  if (slip > Real(0)) {
    const Real magnitude = std::min(c.friction * normal_force, c.tangential_damping * slip);  // N
    tangential = -(magnitude / slip) * v_s;
  }
  return normal_force * n + tangential;
}

// Energy stored in the Hertz spring (J): the integral of k_n delta^(3/2), 2/5 k_n delta^(5/2). Past the
// overlap clamp (raw overlap > the clamped one) the force stays at the clamp's, so the spring holds
// that force times the extra depth more: what it gives back as the overlap relaxes, which the
// blow-up check must count.
template <typename Real>
Real hertz_elastic_energy(Real delta, Real effective_radius, Real effective_modulus, Real raw_delta = Real(0)) {
  const Real k_n = Real(4.0 / 3.0) * effective_modulus * std::sqrt(effective_radius);
  const Real beyond = std::max(Real(0), raw_delta - delta);
  return Real(0.4) * k_n * delta * delta * std::sqrt(delta) + k_n * delta * std::sqrt(delta) * beyond;
}

// Sphere-sphere contact. Positions p (m), centre velocities v (m/s), angular velocities w (rad/s) of
// the bodies the spheres belong to, radii r (m), inverse masses of those bodies (1/kg, 0 for static
// or kinematic: the damping uses the rigid bodies' masses, as LAMMPS does with fix rigid). The
// overlap entering the force is clamped at max_overlap (m) to bound the force after a bad step.
// rest_overlap (m): the pair's overlap when it was bonded, for a pair whose bond broke (BondSet): the
// spheres touch only past it, and the force takes the overlap beyond it.
template <typename Real>
ContactForce<Real> sphere_sphere_contact(const Vec3<Real>& p1, const Vec3<Real>& v1, const Vec3<Real>& w1, Real r1,
                                         Real inverse_mass1, const Vec3<Real>& p2, const Vec3<Real>& v2,
                                         const Vec3<Real>& w2, Real r2, Real inverse_mass2, Real max_overlap,
                                         const ContactCoefficients<Real>& c, Real dt = Real(0),
                                         Vec3<Real>* spring = nullptr, Real rest_overlap = Real(0)) {
  ContactForce<Real> out;
  const Vec3<Real> d = p1 - p2;
  const Real distance = d.norm();
  const Real raw_overlap = r1 + r2 - distance - rest_overlap;
  if (raw_overlap <= Real(0) || distance <= Real(0)) return out;
  const Vec3<Real> n = d / distance;
  out.touching = true;
  out.overlap_clamped = raw_overlap > max_overlap;
  out.overlap = std::min(raw_overlap, max_overlap);
  // Both arms end at the middle of the overlap (p1 + arm1 == p2 + arm2 up to rounding).
  const Vec3<Real> arm1 = -(r1 - Real(0.5) * raw_overlap) * n;
  const Vec3<Real> arm2 = (r2 - Real(0.5) * raw_overlap) * n;
  const Vec3<Real> v_c = (v1 + w1.cross(arm1)) - (v2 + w2.cross(arm2));
  const Real effective_radius = r1 * r2 / (r1 + r2);
  const Real effective_mass = Real(1) / (inverse_mass1 + inverse_mass2);
  out.arm = arm1;
  out.force = hertz_contact_force(n, out.overlap, v_c, effective_radius, effective_mass, c, dt, spring);
  out.elastic_energy = hertz_elastic_energy(out.overlap, effective_radius, c.effective_modulus, raw_overlap);
  return out;
}

// Sphere against a fixed wall surface: `gap` is the signed distance (m) from the wall to the sphere
// centre along the wall normal n (pointing into the free side). The wall has infinite mass and
// infinite radius of curvature (R* = r).
template <typename Real>
ContactForce<Real> sphere_wall_contact(const Vec3<Real>& n, Real gap, const Vec3<Real>& v, const Vec3<Real>& w, Real r,
                                       Real inverse_mass, Real max_overlap, const ContactCoefficients<Real>& c,
                                       Real dt = Real(0), Vec3<Real>* spring = nullptr) {
  ContactForce<Real> out;
  const Real raw_overlap = r - gap;
  if (raw_overlap <= Real(0) || inverse_mass <= Real(0)) return out;
  out.touching = true;
  out.overlap_clamped = raw_overlap > max_overlap;
  out.passed_through = raw_overlap > Real(2) * r;
  out.overlap = std::min(raw_overlap, max_overlap);
  const Vec3<Real> arm = -(r - Real(0.5) * raw_overlap) * n;
  const Vec3<Real> v_c = v + w.cross(arm);
  out.arm = arm;
  out.force = hertz_contact_force(n, out.overlap, v_c, r, Real(1) / inverse_mass, c, dt, spring);
  out.elastic_energy = hertz_elastic_energy(out.overlap, r, c.effective_modulus, raw_overlap);
  return out;
}

}  // namespace ts::sim
