// The World's arrays as bytes and back (sim/state_bytes.h encoding), in one fixed order: what a
// checkpoint stores of the engine's state and what a scene's hash covers. Reading checks that the world
// hangs together, so a damaged or hand-made file cannot index out of range later.
#include "sim/world_bytes.h"

#include <type_traits>

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
  r.get(world.gravity);
  r.get(world.time);
  if (!r.done()) r.fail("bytes left after the world");
  check_world(world, r);
  return world;
}

}  // namespace ts::sim
