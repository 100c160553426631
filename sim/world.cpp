#include "sim/world.h"

#include <algorithm>
#include <cassert>

namespace ts::sim {

std::uint32_t add_body(World& world, const BodyDesc& desc, const std::vector<Eigen::Vector3d>& offsets,
                       const std::vector<double>& radii, std::uint16_t material) {
  assert(offsets.size() == radii.size() && !offsets.empty());
  Bodies& b = world.bodies;
  Particles& p = world.particles;
  const auto index = static_cast<std::uint32_t>(b.size());
  const bool dynamic = desc.motion == MotionType::Dynamic;
  b.position.push_back(desc.position);
  b.orientation.push_back(desc.orientation.normalized());
  b.linear_velocity.push_back(desc.motion == MotionType::Static ? Eigen::Vector3d::Zero() : desc.linear_velocity);
  b.angular_velocity.push_back(desc.motion == MotionType::Static ? Eigen::Vector3d::Zero() : desc.angular_velocity);
  b.inverse_mass.push_back(dynamic ? desc.inverse_mass : 0.0);
  b.inverse_inertia.push_back(dynamic ? desc.inverse_inertia : Eigen::Matrix3d::Zero());
  b.motion.push_back(desc.motion);
  b.first_particle.push_back(static_cast<std::uint32_t>(p.size()));
  b.particle_count.push_back(static_cast<std::uint32_t>(offsets.size()));
  double bound = 0;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    p.body.push_back(index);
    p.offset.push_back(offsets[i]);
    p.radius.push_back(radii[i]);
    p.material.push_back(material);
    bound = std::max(bound, offsets[i].norm() + radii[i]);
  }
  b.bounding_radius.push_back(bound);
  return index;
}

std::uint32_t add_grain(World& world, const GrainShape& grain, std::uint16_t material,
                        const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation,
                        const Eigen::Vector3d& linear_velocity, const Eigen::Vector3d& angular_velocity) {
  BodyDesc desc;
  desc.position = position;
  desc.orientation = orientation;
  desc.linear_velocity = linear_velocity;
  desc.angular_velocity = angular_velocity;
  desc.inverse_mass = 1.0 / grain.mass;
  desc.inverse_inertia = Eigen::Matrix3d::Identity() / grain.inertia;
  desc.motion = MotionType::Dynamic;
  const std::vector<Eigen::Vector3d> offsets(grain.offsets.begin(), grain.offsets.end());
  return add_body(world, desc, offsets, std::vector<double>(4, grain.particle_radius), material);
}

void apply_tracks(World& world, double time) {
  for (const KinematicTrack& track : world.tracks) {
    const KinematicState state = sample_track(track.keys, time);
    world.bodies.position[track.body] = state.position;
    world.bodies.orientation[track.body] = state.orientation;
    world.bodies.linear_velocity[track.body] = state.linear_velocity;
    world.bodies.angular_velocity[track.body] = state.angular_velocity;
  }
}

std::vector<Eigen::Vector3d> particle_positions(const World& world) {
  std::vector<Eigen::Vector3d> out(world.particles.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint32_t b = world.particles.body[i];
    out[i] = world.bodies.position[b] + world.bodies.orientation[b] * world.particles.offset[i];
  }
  return out;
}

namespace {

// World-frame inertia tensor I = R I0 R^T of a dynamic body (kg m^2).
Eigen::Matrix3d world_inertia(const Bodies& b, std::size_t i) {
  const Eigen::Matrix3d r = b.orientation[i].toRotationMatrix();
  return r * b.inverse_inertia[i].inverse() * r.transpose();
}

}  // namespace

double isotropic_inverse_inertia(const Eigen::Matrix3d& inverse_inertia) {
  const Eigen::Matrix3d& m = inverse_inertia;
  const double c = m(0, 0);
  const bool isotropic = m(1, 1) == c && m(2, 2) == c && m(0, 1) == 0 && m(0, 2) == 0 && m(1, 0) == 0 &&
                         m(1, 2) == 0 && m(2, 0) == 0 && m(2, 1) == 0;
  return isotropic && c > 0 ? c : 0.0;
}

Energy energy(const World& world) {
  const Bodies& b = world.bodies;
  Energy e;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.motion[i] != MotionType::Dynamic) continue;
    const double mass = 1.0 / b.inverse_mass[i];
    e.translational += 0.5 * mass * b.linear_velocity[i].squaredNorm();
    if (const double c = isotropic_inverse_inertia(b.inverse_inertia[i]); c > 0) {
      e.rotational += 0.5 * (1.0 / c) * b.angular_velocity[i].squaredNorm();
    } else {
      e.rotational += 0.5 * b.angular_velocity[i].dot(world_inertia(b, i) * b.angular_velocity[i]);
    }
    e.potential -= mass * world.gravity.dot(b.position[i]);
  }
  return e;
}

Eigen::Vector3d linear_momentum(const World& world) {
  const Bodies& b = world.bodies;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.motion[i] == MotionType::Dynamic) p += b.linear_velocity[i] / b.inverse_mass[i];
  }
  return p;
}

Eigen::Vector3d angular_momentum(const World& world) {
  const Bodies& b = world.bodies;
  Eigen::Vector3d l = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.motion[i] != MotionType::Dynamic) continue;
    l += b.position[i].cross(b.linear_velocity[i] / b.inverse_mass[i]) + world_inertia(b, i) * b.angular_velocity[i];
  }
  return l;
}

void grains_to_spheres(World& world) {
  World spheres = world;
  spheres.bodies = {};
  spheres.particles = {};
  spheres.springs = {};
  const Bodies& b = world.bodies;
  for (std::size_t k = 0; k < b.size(); ++k) {
    const std::uint32_t first = b.first_particle[k];
    BodyDesc d{b.position[k],     b.orientation[k],     b.linear_velocity[k], b.angular_velocity[k],
               b.inverse_mass[k], b.inverse_inertia[k], b.motion[k]};
    std::vector<Eigen::Vector3d> offsets(world.particles.offset.begin() + first,
                                         world.particles.offset.begin() + first + b.particle_count[k]);
    std::vector<double> radii(world.particles.radius.begin() + first,
                              world.particles.radius.begin() + first + b.particle_count[k]);
    if (b.motion[k] == MotionType::Dynamic && b.particle_count[k] == 4) {
      const double radius = std::cbrt(4.0) * radii[0];  // m
      offsets = {Eigen::Vector3d::Zero()};
      radii = {radius};
      d.inverse_inertia = Eigen::Matrix3d::Identity() * b.inverse_mass[k] / (0.4 * radius * radius);
    }
    add_body(spheres, d, offsets, radii, world.particles.material[first]);
  }
  world = std::move(spheres);
}

World without_particles(const World& world, const std::function<bool(std::size_t)>& keep) {
  World out = world;
  out.bodies = {};
  out.particles = {};
  out.springs = {};
  out.tracks = {};
  const Bodies& b = world.bodies;
  std::vector<std::int64_t> new_index(b.size(), -1);  // -1: dropped
  for (std::size_t k = 0; k < b.size(); ++k) {
    const std::uint32_t first = b.first_particle[k];
    std::vector<Eigen::Vector3d> offsets;
    std::vector<double> radii;
    for (std::uint32_t i = first; i < first + b.particle_count[k]; ++i) {
      if (b.motion[k] == MotionType::Dynamic ? !keep(first) : !keep(i)) continue;
      offsets.push_back(world.particles.offset[i]);
      radii.push_back(world.particles.radius[i]);
    }
    if (offsets.empty()) continue;
    const BodyDesc d{b.position[k],     b.orientation[k],     b.linear_velocity[k], b.angular_velocity[k],
                     b.inverse_mass[k], b.inverse_inertia[k], b.motion[k]};
    new_index[k] = add_body(out, d, offsets, radii, world.particles.material[first]);
  }
  for (KinematicTrack track : world.tracks) {
    if (new_index[track.body] < 0) continue;
    track.body = static_cast<std::uint32_t>(new_index[track.body]);
    out.tracks.push_back(std::move(track));
  }
  return out;
}

}  // namespace ts::sim
