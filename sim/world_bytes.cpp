// The World's arrays as bytes and back (sim/state_bytes.h encoding), in one fixed order: what a
// checkpoint stores of the engine's state and what a scene's hash covers. Reading checks that the world
// hangs together, so a damaged or hand-made file cannot index out of range later.
#include "sim/world_bytes.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "core/checked_values.h"
#include "sim/contact_model.h"

namespace ts::sim {
namespace {
// The body arrays in file order, through `fn` (writing and reading alike).
template <typename AnyBodies, typename Fn>
void for_each_body_array(AnyBodies& b, Fn&& fn) {
  fn(b.position);
  fn(b.orientation);
  fn(b.linear_velocity);
  fn(b.angular_velocity);
  fn(b.inverse_mass);
  fn(b.inverse_inertia);
  fn(b.bounding_radius);
  fn(b.motion);
  fn(b.first_particle);
  fn(b.particle_count);
}

void put_bodies(ByteWriter& w, const Bodies& b) {
  for_each_body_array(b, [&](const auto& values) { w.put_vector(values); });
}

void get_bodies(ByteReader& r, Bodies& b) {
  for_each_body_array(b, [&](auto& values) {
    values = r.get_vector<typename std::remove_reference_t<decltype(values)>::value_type>();
  });
}

// The fields of a smooth wall in file order, through `fn` (writing and reading alike).
template <typename Plane, typename Fn>
void for_each_plane_field(Plane& p, Fn&& fn) {
  fn(p.point);
  fn(p.normal);
  fn(p.material);
}
template <typename Cylinder, typename Fn>
void for_each_cylinder_field(Cylinder& c, Fn&& fn) {
  fn(c.axis);
  fn(c.radius);
  fn(c.z_min);
  fn(c.z_max);
  fn(c.material);
}

void put_walls(ByteWriter& w, const Walls& walls) {
  const auto put = [&](const auto& value) { w.put(value); };
  put_each(w, walls.planes, [&](const PlaneWall& p) { for_each_plane_field(p, put); });
  put_each(w, walls.cylinders, [&](const CylinderWall& c) { for_each_cylinder_field(c, put); });
}

void get_walls(ByteReader& r, Walls& walls) {
  const auto get = [&](auto& value) { r.get(value); };
  walls.planes = get_each<PlaneWall>(r, 50, [&](PlaneWall& p) { for_each_plane_field(p, get); });
  walls.cylinders = get_each<CylinderWall>(r, 42, [&](CylinderWall& c) { for_each_cylinder_field(c, get); });
}

void put_tracks(ByteWriter& w, const std::vector<KinematicTrack>& tracks) {
  put_each(w, tracks, [&](const KinematicTrack& t) {
    w.put(t.body);
    put_each(w, t.keys, [&](const Keyframe& k) {
      w.put(k.time);
      w.put(k.position);
      w.put(k.orientation);
    });
  });
}

std::vector<KinematicTrack> get_tracks(ByteReader& r) {
  return get_each<KinematicTrack>(r, 12, [&](KinematicTrack& t) {
    r.get(t.body);
    t.keys = get_each<Keyframe>(r, 64, [&](Keyframe& k) {
      r.get(k.time);
      r.get(k.position);
      r.get(k.orientation);
    });
  });
}

void put_materials(ByteWriter& w, const std::vector<Material>& materials) {
  put_each(w, materials, [&](const Material& m) {
    for (double v :
         {m.youngs_modulus, m.poisson_ratio, m.restitution, m.friction, m.tangential_damping, m.density})
      w.put(v);
  });
}

std::vector<Material> get_materials(ByteReader& r) {
  return get_each<Material>(r, 48, [&](Material& m) {
    for (double* v : {&m.youngs_modulus, &m.poisson_ratio, &m.restitution, &m.friction, &m.tangential_damping,
                      &m.density})
      r.get(*v);
  });
}

void put_bonds(ByteWriter& w, const World& world) {
  put_each(w, world.bond_materials, [&](const BondMaterial& m) {
    for (double v : {m.youngs_modulus, m.stiffness_ratio, m.radius_factor, m.tensile_strength, m.shear_strength,
                     m.strength_spread, m.bond_distance})
      w.put(v);
  });
  const BondSet& b = world.bonds;
  for (const auto* v : {&b.a, &b.b}) w.put_vector(*v);
  w.put_vector(b.material);
  w.put_vector(b.tensile_strength);
  w.put_vector(b.shear_strength);
  w.put_vector(b.intact);
  put_each(w, b.state, [&](const BondState<double>& s) {
    w.put(s.normal_force);
    w.put(s.shear_force);
    w.put(s.twisting_moment);
    w.put(s.bending_moment);
  });
  w.put_vector(b.rest_overlap);
}

void get_bonds(ByteReader& r, World& world) {
  world.bond_materials = get_each<BondMaterial>(r, 56, [&](BondMaterial& m) {
    for (double* v : {&m.youngs_modulus, &m.stiffness_ratio, &m.radius_factor, &m.tensile_strength,
                      &m.shear_strength, &m.strength_spread, &m.bond_distance})
      r.get(*v);
  });
  BondSet& b = world.bonds;
  b.a = r.get_vector<std::uint32_t>();
  b.b = r.get_vector<std::uint32_t>();
  b.material = r.get_vector<std::uint16_t>();
  b.tensile_strength = r.get_vector<double>();
  b.shear_strength = r.get_vector<double>();
  b.intact = r.get_vector<std::uint8_t>();
  b.state = get_each<BondState<double>>(r, 64, [&](BondState<double>& s) {
    r.get(s.normal_force);
    r.get(s.shear_force);
    r.get(s.twisting_moment);
    r.get(s.bending_moment);
  });
  b.rest_overlap = r.get_vector<double>();
}

// Bonds join two different particles of the world, name a bond material, and carry finite loads
// within strengths that are positive: a crafted file must not index out of range or resume into NaN.
void check_bonds(const World& w, ByteReader& r) {
  const BondSet& b = w.bonds;
  const std::size_t n = b.size();
  if (b.b.size() != n || b.material.size() != n || b.tensile_strength.size() != n || b.shear_strength.size() != n ||
      b.intact.size() != n || b.state.size() != n || b.rest_overlap.size() != n)
    r.fail("the bonds' arrays differ in length");
  for (std::size_t k = 0; k < n; ++k) {
    if (b.a[k] >= w.particles.size() || b.b[k] >= w.particles.size() || b.a[k] == b.b[k] ||
        b.material[k] >= w.bond_materials.size() || b.intact[k] > 1)
      r.fail(fmt::format("bond {} names missing particles or a missing bond material", k));
    const BondState<double>& s = b.state[k];
    if (!(b.tensile_strength[k] > 0 && b.shear_strength[k] > 0 && std::isfinite(b.tensile_strength[k]) &&
          std::isfinite(b.shear_strength[k]) && std::isfinite(s.normal_force) && s.shear_force.allFinite() &&
          std::isfinite(s.twisting_moment) && s.bending_moment.allFinite()))
      r.fail(fmt::format("bond {} has a strength that is not finite and > 0, or a load that is not finite", k));
    if (!(b.rest_overlap[k] >= 0 && b.rest_overlap[k] < w.particles.radius[b.a[k]] + w.particles.radius[b.b[k]]))
      r.fail(fmt::format("bond {} has a rest overlap that is not in [0, r_a + r_b)", k));
  }
  for (std::size_t i = 0; i < w.bond_materials.size(); ++i) {
    if (const std::string problem = validate(w.bond_materials[i]); !problem.empty())
      r.fail(fmt::format("bond material of entry {}: {}", i, problem));
  }
}

// Does the world hang together (a damaged or hand-made file must not index out of range later)?
void check_world(const World& w, ByteReader& r) {
  const Bodies& b = w.bodies;
  const std::size_t n = b.size(), p = w.particles.size();
  const bool bodies_ok = b.orientation.size() == n && b.linear_velocity.size() == n &&
                         b.angular_velocity.size() == n && b.inverse_mass.size() == n &&
                         b.inverse_inertia.size() == n && b.bounding_radius.size() == n &&
                         b.motion.size() == n && b.first_particle.size() == n && b.particle_count.size() == n;
  const Particles& q = w.particles;
  const bool particles_ok = q.offset.size() == p && q.radius.size() == p && q.material.size() == p;
  if (!bodies_ok || !particles_ok) r.fail("the world's arrays differ in length");
  for (std::size_t k = 0; k < n; ++k) {
    if (std::uint64_t{b.first_particle[k]} + b.particle_count[k] > p)
      r.fail("a body's particles lie past the last");
  }
  for (std::size_t i = 0; i < p; ++i) {
    if (q.body[i] >= n || q.material[i] >= w.materials.size())
      r.fail("a particle names a missing body or material");
  }
  for (MotionType m : b.motion) {
    if (m != MotionType::Dynamic && m != MotionType::Kinematic && m != MotionType::Static)
      r.fail("an unknown motion type");
  }
  for (const KinematicTrack& t : w.tracks) {
    if (t.body >= n || t.keys.empty()) r.fail("a kinematic track names a missing body");
  }
  const std::size_t slots = w.springs.partner.size();
  if (w.springs.displacement.size() != slots || slots % ContactSprings::kSlots != 0)
    r.fail("damaged contact springs");
}

// The numbers a fresh scene's checks guarantee, checked again on a world read back: a crafted file
// with a recomputed checksum must not resume into NaN outputs. Each refusal names the field.
class ValueCheck {
 public:
  static constexpr std::size_t kWhole = static_cast<std::size_t>(-1);  // a field that is one value

  explicit ValueCheck(ByteReader& r) : r_(r) {}
  template <typename Derived>
  void finite(const Eigen::MatrixBase<Derived>& v, const std::string& field,
              std::size_t index = kWhole) const {
    if (!v.allFinite()) r_.fail(fmt::format("{} is not finite", name(field, index)));
  }
  void finite(double v, const std::string& field, std::size_t index = kWhole) const {
    if (!std::isfinite(v)) r_.fail(fmt::format("{} is {} (must be finite)", name(field, index), v));
  }
  void positive(double v, const std::string& field, std::size_t index) const {
    if (!(v > 0) || !std::isfinite(v))
      r_.fail(fmt::format("{} is {} (must be finite and > 0)", name(field, index), v));
  }
  void unit(const Eigen::Quaterniond& q, const std::string& field, std::size_t index) const {
    const std::string problem = quaternion_problem(q.coeffs());
    if (!problem.empty()) r_.fail(fmt::format("{}: {}", name(field, index), problem));
  }

 private:
  static std::string name(const std::string& field, std::size_t index) {
    return index == kWhole ? field : fmt::format("{} of entry {}", field, index);
  }
  ByteReader& r_;
};

// What a fresh body's inverse inertia always is: symmetric positive definite, its principal moments
// in the range a scene's are held to. A crafted one that is finite but not invertible in doubles (1e308 on the
// diagonal, found by fuzz_checkpoint) made the rotational energy NaN while the state stayed finite.
std::string inverse_inertia_problem(const Eigen::Matrix3d& inverse_inertia) {
  const double scale = inverse_inertia.cwiseAbs().maxCoeff();
  if (!((inverse_inertia - inverse_inertia.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale))
    return "not symmetric";
  const Eigen::Vector3d eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inverse_inertia,
                                                                                     Eigen::EigenvaluesOnly)
                                          .eigenvalues();
  if (!(eigenvalues.minCoeff() > 0)) return fmt::format("not positive definite (eigenvalue {:.3g})", eigenvalues.minCoeff());
  // The principal moments in the range a scene's are checked against (core/checked_values.h), so the
  // 3x3 inverse the step takes, and the rotational energy through it, stay finite.
  for (double moment : eigenvalues.cwiseInverse())
    if (!mass_fits(moment))
      return fmt::format("a principal moment of {:.3g} kg m^2, outside [{:.0e}, {:.0e}]", moment, kLeastMass, kMostMass);
  return {};
}

void check_body_values(const Bodies& b, const ValueCheck& check, ByteReader& r) {
  for (std::size_t k = 0; k < b.size(); ++k) {
    check.finite(b.position[k], "body position", k);
    check.unit(b.orientation[k], "body orientation", k);
    check.finite(b.linear_velocity[k], "body linear_velocity", k);
    // No faster than light, as a scene's velocities (core/checked_values.h): 1e300 m/s is finite, but
    // its kinetic energy is not.
    if (b.linear_velocity[k].norm() > kMaxSpeed)
      r.fail(fmt::format("body linear_velocity of entry {} is {:.3g} m/s, faster than light", k,
                         b.linear_velocity[k].norm()));
    check.finite(b.angular_velocity[k], "body angular_velocity", k);
    if (b.angular_velocity[k].norm() * b.bounding_radius[k] > kMaxSpeed)
      r.fail(fmt::format("body angular_velocity of entry {} is {:.3g} rad/s: its particles move faster than light",
                         k, b.angular_velocity[k].norm()));
    check.finite(b.inverse_inertia[k], "body inverse_inertia", k);
    check.finite(b.bounding_radius[k], "body bounding_radius", k);
    // A dynamic body moves by its forces times its inverse mass: 0 would freeze it, inf fling it.
    if (b.motion[k] == MotionType::Dynamic) {
      check.positive(b.inverse_mass[k], "body inverse_mass (dynamic)", k);
      // Finite is not enough: 1e308 is a mass of 1e-308 kg that any contact flings out of the grid
      // (found by fuzz_checkpoint). A scene's masses lie in core/checked_values.h's range.
      if (!mass_fits(1.0 / b.inverse_mass[k]))
        r.fail(fmt::format("body inverse_mass of entry {} is {:.3g} 1/kg: a mass of {:.3g} kg, outside [{:.0e}, {:.0e}] kg",
                           k, b.inverse_mass[k], 1.0 / b.inverse_mass[k], kLeastMass, kMostMass));
      if (const std::string problem = inverse_inertia_problem(b.inverse_inertia[k]); !problem.empty())
        r.fail(fmt::format("body inverse_inertia of entry {}: {}", k, problem));
    } else if (b.inverse_mass[k] != 0 || !b.inverse_inertia[k].isZero(0.0)) {
      r.fail(fmt::format("body inverse_mass or inverse_inertia of entry {} is not 0 (must be for a kinematic or "
                         "static body)",
                         k));
    }
  }
}

// Every particle within the grid's reach, as a fresh scene's are (kMaxCellCoordinate cells of the
// largest diameter): a crafted checkpoint resumed a particle 8.6e143 cells out to exit 0 (found by
// fuzz_checkpoint). Positions, offsets and orientations are checked finite before.
void check_particle_reach(const World& w, ByteReader& r) {
  double cell = 0;  // m
  for (double radius : w.particles.radius) cell = std::max(cell, 2 * radius);
  const std::vector<Eigen::Vector3d> positions = particle_positions(w);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double cells = positions[i].cwiseAbs().maxCoeff() / cell;
    if (cells <= kMaxCellCoordinate) continue;
    r.fail(fmt::format("particle position of entry {} lies {:.3g} grid cells of {:.3g} m from the origin; at "
                       "most {:.0g} fit",
                       i, cells, cell, kMaxCellCoordinate));
  }
}

void check_world_values(const World& w, ByteReader& r) {
  const ValueCheck check(r);
  check_body_values(w.bodies, check, r);
  for (std::size_t i = 0; i < w.particles.size(); ++i) {
    check.finite(w.particles.offset[i], "particle offset", i);
    check.positive(w.particles.radius[i], "particle radius", i);
  }
  for (std::size_t i = 0; i < w.springs.displacement.size(); ++i)
    check.finite(w.springs.displacement[i], "spring displacement", i);
  for (std::size_t i = 0; i < w.walls.planes.size(); ++i) {
    check.finite(w.walls.planes[i].point, "plane wall point", i);
    const std::string problem = unit_vector_problem(w.walls.planes[i].normal);
    if (!problem.empty()) r.fail(fmt::format("plane wall normal of entry {}: {}", i, problem));
  }
  for (std::size_t i = 0; i < w.walls.cylinders.size(); ++i) {
    check.finite(w.walls.cylinders[i].axis, "cylinder wall axis", i);
    check.positive(w.walls.cylinders[i].radius, "cylinder wall radius", i);
  }
  for (std::size_t i = 0; i < w.materials.size(); ++i) {
    if (const std::string problem = validate(w.materials[i]); !problem.empty())
      r.fail(fmt::format("material of entry {}: {}", i, problem));
  }
  for (const KinematicTrack& t : w.tracks) {
    for (std::size_t i = 0; i < t.keys.size(); ++i) {
      check.finite(t.keys[i].time, "kinematic key time", i);
      check.finite(t.keys[i].position, "kinematic key position", i);
      check.unit(t.keys[i].orientation, "kinematic key orientation", i);
    }
  }
  check.finite(w.gravity, "gravity");
  check.finite(w.time, "time");
  check_particle_reach(w, r);
}

}  // namespace

std::string world_bytes(const World& world) {
  ByteWriter w;
  put_bodies(w, world.bodies);
  w.put_vector(world.particles.body);
  w.put_vector(world.particles.offset);
  w.put_vector(world.particles.radius);
  w.put_vector(world.particles.material);
  w.put_vector(world.springs.partner);
  w.put_vector(world.springs.displacement);
  put_walls(w, world.walls);
  put_tracks(w, world.tracks);
  put_materials(w, world.materials);
  put_bonds(w, world);
  w.put(world.gravity);
  w.put(world.time);
  return w.bytes();
}

World world_from_bytes(ByteReader& r) {
  World world;
  get_bodies(r, world.bodies);
  world.particles.body = r.get_vector<std::uint32_t>();
  world.particles.offset = r.get_vector<Eigen::Vector3d>();
  world.particles.radius = r.get_vector<double>();
  world.particles.material = r.get_vector<std::uint16_t>();
  world.springs.partner = r.get_vector<std::int64_t>();
  world.springs.displacement = r.get_vector<Eigen::Vector3d>();
  get_walls(r, world.walls);
  world.tracks = get_tracks(r);
  world.materials = get_materials(r);
  get_bonds(r, world);
  r.get(world.gravity);
  r.get(world.time);
  if (!r.done()) r.fail("bytes left after the world");
  check_world(world, r);
  check_bonds(world, r);
  check_world_values(world, r);
  return world;
}

}  // namespace ts::sim
