#include "sim/cpu_reference.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>

#include "core/error.h"

namespace ts::sim {

std::uint32_t hash_cell(const Eigen::Vector3i& c, std::uint32_t table_size) {
  const std::uint32_t h = static_cast<std::uint32_t>(c.x()) + static_cast<std::uint32_t>(c.y()) * 19349663u +
                          static_cast<std::uint32_t>(c.z()) * 83492791u;
  return h & (table_size - 1u);
}

void build_neighbour_grid(const std::vector<Eigen::Vector3d>& positions, double cell_size, NeighbourGrid& grid) {
  const auto n = static_cast<std::uint32_t>(positions.size());
  grid.cell_size = cell_size;
  // At least 4 buckets, so the three buckets of a row (visit_contacts) are always distinct.
  grid.table_size = std::bit_ceil(std::max<std::uint32_t>(2 * n, 4));
  grid.cell.resize(n);
  std::vector<std::uint32_t> bucket(n);
  tbb::parallel_for(std::uint32_t{0}, n, [&](std::uint32_t i) {
    // A blown-up state still gets a cell (NaN or huge coordinates would overflow the int cast);
    // the stability check rejects it after the step.
    const Eigen::Array3d cell = (positions[i] / cell_size).array().floor();
    grid.cell[i] = Eigen::Vector3i::Zero();
    if (cell.allFinite()) grid.cell[i] = cell.max(-1e9).min(1e9).cast<int>().matrix();
    bucket[i] = hash_cell(grid.cell[i], grid.table_size);
  });
  // Counting sort: count, exclusive scan, scatter in particle order (buckets list ids ascending).
  grid.bucket_start.assign(grid.table_size + 1, 0);
  for (std::uint32_t i = 0; i < n; ++i) ++grid.bucket_start[bucket[i] + 1];
  for (std::uint32_t b = 0; b < grid.table_size; ++b) grid.bucket_start[b + 1] += grid.bucket_start[b];
  std::vector<std::uint32_t> fill(grid.bucket_start.begin(), grid.bucket_start.end() - 1);
  grid.sorted.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) grid.sorted[fill[bucket[i]]++] = i;
}

CpuStepper::CpuStepper(const World& world, const StepSettings& settings) : settings_(settings) {
  reset_energy_reference(world);
}

void CpuStepper::reset_energy_reference(const World& world) {
  if (world.materials.size() != material_count_) {
    material_count_ = world.materials.size();
    pairs_.clear();
    for (const Material& a : world.materials) {
      for (const Material& b : world.materials) {
        const PairCoefficients p =
            make_pair_coefficients(a, b, settings_.normal_damping, settings_.thesis_reference_speed);
        pairs_.push_back(ContactCoefficients<double>::from(p, settings_.normal_damping));
      }
    }
  }
  dynamic_mass_ = 0;
  max_diameter_ = 0;
  for (std::size_t i = 0; i < world.bodies.size(); ++i) {
    if (world.bodies.motion[i] == MotionType::Dynamic) dynamic_mass_ += 1.0 / world.bodies.inverse_mass[i];
  }
  for (double r : world.particles.radius) max_diameter_ = std::max(max_diameter_, 2 * r);
  reference_pending_ = true;  // taken at the next step, when the contacts' spring energy is known
}

namespace {

// Everything one particle's gather produces.
struct ParticleContacts {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   // N
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  // N m, about the particle centre
  std::uint32_t pairs = 0, walls = 0, overlap_clamps = 0;
  double max_overlap_ratio = 0;
  double elastic_energy = 0;  // J

  void add(const ContactForce<double>& c, double smaller_radius, bool count) {
    if (!c.touching) return;
    force += c.force;
    torque += c.arm.cross(c.force);
    if (!count) return;
    max_overlap_ratio = std::max(max_overlap_ratio, c.overlap / smaller_radius);
    elastic_energy += c.elastic_energy;
    overlap_clamps += c.overlap_clamped ? 1 : 0;
  }
};

// Each contact is counted once: walls and non-dynamic partners by the dynamic particle (the only
// side that computes them), pairs of dynamic particles by the lower id.
bool counted_here(const World& world, std::uint32_t i, std::int64_t partner) {
  if (partner < 0) return true;
  const auto j = static_cast<std::uint32_t>(partner);
  return world.bodies.inverse_mass[world.particles.body[j]] == 0 || i < j;
}

double max_radius(const World& world) {
  double r = 0;
  for (double x : world.particles.radius) r = std::max(r, x);
  return r;
}

}  // namespace

template <typename Fn>
void CpuStepper::visit_contacts(const World& world, std::uint32_t i, Fn&& fn, SpringSlots* springs) const {
  const Bodies& b = world.bodies;
  const Particles& p = world.particles;
  const double overlap_ratio_cap = settings_.max_overlap_ratio > 0 ? settings_.max_overlap_ratio : 1e30;
  const std::uint32_t bi = p.body[i];
  const double ri = p.radius[i];
  const double inverse_mass_i = b.inverse_mass[bi];
  const Eigen::Vector3d& xi = position_[i];
  const Eigen::Vector3d& wi = b.angular_velocity[bi];
  const double dt = settings_.dt;
  // The contact's spring (zero for a new contact), or null without springs.
  Eigen::Vector3d spring = Eigen::Vector3d::Zero();
  auto find_spring = [&](std::int64_t partner) -> Eigen::Vector3d* {
    if (!springs) return nullptr;
    spring.setZero();
    for (std::size_t k = 0; k < ContactSprings::kSlots && springs->old_partner; ++k) {
      if (springs->old_partner[k] == partner) spring = springs->old_displacement[k];
    }
    return &spring;
  };
  auto keep_spring = [&](std::int64_t partner) {
    if (!springs || !springs->new_partner) return;
    if (springs->used == ContactSprings::kSlots) {
      ++springs->overflows;
      return;
    }
    springs->new_partner[springs->used] = partner;
    springs->new_displacement[springs->used] = spring;
    ++springs->used;
  };
  // Other bodies' particles in the 27 cells around, row by row (dz, dy), each row's three cells in
  // increasing x and each bucket in increasing id. A row is three consecutive buckets (see
  // hash_cell), so it is one contiguous scan unless it wraps around the table's end.
  const Eigen::Vector3i& own_cell = grid_.cell[i];
  const std::uint32_t last_bucket = grid_.table_size - 1;
  auto visit_bucket_range = [&](std::uint32_t first, std::uint32_t end, int y, int z) {
    for (std::uint32_t s = first; s < end; ++s) {
      const Candidate& other = candidates_[s];
      // A cell of another row hashed here, or a partner that cannot receive a force.
      if (other.cell.y() != y || other.cell.z() != z || std::abs(other.cell.x() - own_cell.x()) > 1) continue;
      if (other.body == bi || (inverse_mass_i == 0 && other.inverse_mass == 0)) continue;
      const double rj = other.radius;
      // Only touching pairs go on (the force repeats this test with the distance itself).
      if ((xi - other.position).squaredNorm() >= (ri + rj) * (ri + rj)) continue;
      const std::uint32_t j = other.particle;
      const std::uint32_t bj = other.body;
      const auto& coefficients = pairs_[p.material[i] * material_count_ + p.material[j]];
      const double smaller = std::min(ri, rj);
      const auto partner = static_cast<std::int64_t>(j);
      const ContactForce<double> f = sphere_sphere_contact(
          xi, velocity_[i], wi, ri, inverse_mass_i, position_[j], velocity_[j], b.angular_velocity[bj], rj,
          b.inverse_mass[bj], overlap_ratio_cap * smaller, coefficients, dt, find_spring(partner));
      if (!f.touching) continue;
      keep_spring(partner);
      fn(f, partner, smaller);
    }
  };
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      const int y = own_cell.y() + dy, z = own_cell.z() + dz;
      const std::uint32_t h = hash_cell(Eigen::Vector3i(own_cell.x() - 1, y, z), grid_.table_size);
      if (h + 2 <= last_bucket) {
        visit_bucket_range(grid_.bucket_start[h], grid_.bucket_start[h + 3], y, z);
      } else {
        for (std::uint32_t k = 0; k < 3; ++k) {
          const std::uint32_t hk = (h + k) & last_bucket;
          visit_bucket_range(grid_.bucket_start[hk], grid_.bucket_start[hk + 1], y, z);
        }
      }
    }
  }
  // Smooth walls, in declaration order: planes, then cylinders (partner -1 - wall index).
  const double inverse_mass = b.inverse_mass[bi];
  const double max_overlap = overlap_ratio_cap * ri;
  std::int64_t wall_index = 0;
  for (const PlaneWall& wall : world.walls.planes) {
    const auto& coefficients = pairs_[p.material[i] * material_count_ + wall.material];
    const double gap = wall.normal.dot(position_[i] - wall.point);
    if (gap < ri) {
      const ContactForce<double> f = sphere_wall_contact(wall.normal, gap, velocity_[i], wi, ri, inverse_mass,
                                                         max_overlap, coefficients, dt, find_spring(-1 - wall_index));
      if (f.touching) {
        keep_spring(-1 - wall_index);
        fn(f, -1 - wall_index, ri);
      }
    }
    ++wall_index;
  }
  for (const CylinderWall& wall : world.walls.cylinders) {
    const Eigen::Vector3d& x = position_[i];
    const Eigen::Vector2d radial = x.head<2>() - wall.axis;
    const double distance = radial.norm();
    if (x.z() >= wall.z_min && x.z() <= wall.z_max && distance > 0) {
      const Eigen::Vector3d normal(-radial.x() / distance, -radial.y() / distance, 0.0);
      const auto& coefficients = pairs_[p.material[i] * material_count_ + wall.material];
      const ContactForce<double> f = sphere_wall_contact(normal, wall.radius - distance, velocity_[i], wi, ri,
                                                         inverse_mass, max_overlap, coefficients, dt,
                                                         find_spring(-1 - wall_index));
      if (f.touching) {
        keep_spring(-1 - wall_index);
        fn(f, -1 - wall_index, ri);
      }
    }
    ++wall_index;
  }
}

void CpuStepper::prepare_particles(const World& world) {
  const Bodies& b = world.bodies;
  const Particles& p = world.particles;
  const auto n = static_cast<std::uint32_t>(p.size());
  position_.resize(n);
  velocity_.resize(n);
  force_.resize(n);
  torque_.resize(n);
  // Particle world positions and velocities from the body poses (eqs. 3.42, 3.43).
  tbb::parallel_for(std::uint32_t{0}, n, [&](std::uint32_t i) {
    const std::uint32_t k = p.body[i];
    const Eigen::Vector3d arm = b.orientation[k] * p.offset[i];
    position_[i] = b.position[k] + arm;
    velocity_[i] = b.linear_velocity[k] + b.angular_velocity[k].cross(arm);
  });
  const double cell = n > 0 ? 2 * max_radius(world) : 1.0;  // m
  build_neighbour_grid(position_, cell, grid_);
  candidates_.resize(n);
  tbb::parallel_for(std::uint32_t{0}, n, [&](std::uint32_t s) {
    const std::uint32_t j = grid_.sorted[s];
    candidates_[s] = {position_[j], p.radius[j], b.inverse_mass[p.body[j]], grid_.cell[j], p.body[j], j};
  });
}

std::vector<ContactRecord> CpuStepper::contacts(const World& world) {
  if (world.materials.size() != material_count_) reset_energy_reference(world);
  prepare_particles(world);
  std::vector<ContactRecord> records;
  for (std::uint32_t i = 0; i < world.particles.size(); ++i) {
    if (world.bodies.inverse_mass[world.particles.body[i]] == 0) continue;
    // Springs are read (the forces include them) but not advanced.
    SpringSlots slots;
    const bool springs = settings_.tangential == TangentialModel::Spring &&
                         world.springs.partner.size() >= (i + 1) * ContactSprings::kSlots;
    if (springs) {
      slots.old_partner = &world.springs.partner[i * ContactSprings::kSlots];
      slots.old_displacement = &world.springs.displacement[i * ContactSprings::kSlots];
    }
    visit_contacts(
        world, i,
        [&](const ContactForce<double>& f, std::int64_t partner, double) {
          if (!counted_here(world, i, partner)) return;
          records.push_back({i, partner, position_[i] + f.arm, f.force, f.overlap});
        },
        springs ? &slots : nullptr);
  }
  return records;
}

void CpuStepper::compute_forces(const World& world, StepStats& stats) {
  prepare_particles(world);
  const auto n = static_cast<std::uint32_t>(world.particles.size());

  const bool springs = settings_.tangential == TangentialModel::Spring;
  constexpr std::size_t K = ContactSprings::kSlots;
  // Each particle reads only its own old slots and writes only its own new ones: thread-safe. Grains
  // appended since the last step (emitters) have no slots yet; everyone else keeps theirs.
  const std::size_t old_particles = world.springs.partner.size() / K;
  if (springs) {
    next_springs_.partner.assign(std::size_t{n} * K, ContactSprings::kNoPartner);
    next_springs_.displacement.assign(std::size_t{n} * K, Eigen::Vector3d::Zero());
  }
  std::vector<ParticleContacts> contacts(n);
  std::vector<std::size_t> overflows(springs ? n : 0, 0);
  tbb::parallel_for(std::uint32_t{0}, n, [&](std::uint32_t i) {
    ParticleContacts& out = contacts[i];
    // Static and kinematic particles need no force: their partners compute their own side.
    if (world.bodies.inverse_mass[world.particles.body[i]] == 0) return;
    SpringSlots slots;
    if (springs) {
      if (i < old_particles) {
        slots.old_partner = &world.springs.partner[i * K];
        slots.old_displacement = &world.springs.displacement[i * K];
      }
      slots.new_partner = &next_springs_.partner[i * K];
      slots.new_displacement = &next_springs_.displacement[i * K];
    }
    visit_contacts(
        world, i,
        [&](const ContactForce<double>& f, std::int64_t partner, double smaller_radius) {
          const bool wall = partner < 0;
          const bool counted = counted_here(world, i, partner);
          out.add(f, smaller_radius, counted);
          out.pairs += (!wall && counted) ? 1 : 0;
          out.walls += wall ? 1 : 0;
        },
        springs ? &slots : nullptr);
    if (springs) overflows[i] = slots.overflows;
  });
  for (std::size_t o : overflows) stats.spring_overflows += o;

  // Statistics in particle order.
  for (std::uint32_t i = 0; i < n; ++i) {
    force_[i] = contacts[i].force;
    torque_[i] = contacts[i].torque;
    stats.contacts += contacts[i].pairs;
    stats.wall_contacts += contacts[i].walls;
    stats.overlap_clamps += contacts[i].overlap_clamps;
    stats.elastic_energy += contacts[i].elastic_energy;
    stats.max_overlap_ratio = std::max(stats.max_overlap_ratio, contacts[i].max_overlap_ratio);
  }
}

namespace {

// q + 1/2 [w, 0] q dt, normalised (eq. 3.50).
Eigen::Quaterniond advance_orientation(const Eigen::Quaterniond& q, const Eigen::Vector3d& w, double dt) {
  const Eigen::Quaterniond spin = Eigen::Quaterniond(0.0, w.x(), w.y(), w.z()) * q;
  Eigen::Quaterniond next(q.coeffs() + 0.5 * dt * spin.coeffs());
  next.normalize();
  return next;
}

// I(t)^-1 = R I0^-1 R^T (eq. 3.48).
Eigen::Matrix3d world_inverse_inertia(const Eigen::Quaterniond& q, const Eigen::Matrix3d& body_inverse_inertia) {
  const Eigen::Matrix3d r = q.toRotationMatrix();
  return r * body_inverse_inertia * r.transpose();
}

}  // namespace

void CpuStepper::integrate(World& world, StepStats& stats) const {
  Bodies& b = world.bodies;
  const double dt = settings_.dt;
  const double max_speed = settings_.cfl > 0 ? settings_.cfl * grid_.cell_size / dt : 1e300;  // m/s
  const auto count = static_cast<std::uint32_t>(b.size());
  std::vector<std::uint8_t> clamped(count, 0);  // bit 0: linear, bit 1: angular

  tbb::parallel_for(std::uint32_t{0}, count, [&](std::uint32_t k) {
    if (b.motion[k] == MotionType::Static) return;
    if (b.motion[k] == MotionType::Kinematic) {
      b.position[k] += b.linear_velocity[k] * dt;
      b.orientation[k] = advance_orientation(b.orientation[k], b.angular_velocity[k], dt);
      return;
    }
    // Per-body sums in particle order (deterministic).
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
    for (std::uint32_t i = b.first_particle[k]; i < b.first_particle[k] + b.particle_count[k]; ++i) {
      force += force_[i];
      torque += (position_[i] - b.position[k]).cross(force_[i]) + torque_[i];
    }
    const Eigen::Vector3d acceleration = world.gravity + b.inverse_mass[k] * force;
    // Rotation first (eqs. 3.47-3.50) through the angular momentum, which is what the torque
    // changes; for the isotropic grains this is plain w += I^-1 tau dt.
    const Eigen::Matrix3d inverse_inertia_now = world_inverse_inertia(b.orientation[k], b.inverse_inertia[k]);
    const Eigen::Vector3d momentum = inverse_inertia_now.inverse() * b.angular_velocity[k] + torque * dt;
    Eigen::Vector3d w_move = b.angular_velocity[k];
    if (settings_.integrator == Integrator::SemiImplicitEuler) w_move = inverse_inertia_now * momentum;
    b.orientation[k] = advance_orientation(b.orientation[k], w_move, dt);
    Eigen::Vector3d w = world_inverse_inertia(b.orientation[k], b.inverse_inertia[k]) * momentum;

    Eigen::Vector3d v = b.linear_velocity[k] + acceleration * dt;
    const Eigen::Vector3d v_move = settings_.integrator == Integrator::SemiImplicitEuler ? v : b.linear_velocity[k];
    b.position[k] += v_move * dt;

    const double reach = b.bounding_radius[k];
    if (v.norm() > max_speed) {
      v *= max_speed / v.norm();
      clamped[k] |= 1;
    }
    if (w.norm() * reach > max_speed) {
      w *= max_speed / (w.norm() * reach);
      clamped[k] |= 2;
    }
    if (settings_.angular_damping_rate > 0 && v.norm() + w.norm() * reach < settings_.angular_damping_speed) {
      w *= std::max(0.0, 1.0 - settings_.angular_damping_rate * dt);
    }
    b.linear_velocity[k] = v;
    b.angular_velocity[k] = w;
  });
  for (std::uint8_t c : clamped) {
    stats.velocity_clamps += c & 1;
    stats.angular_velocity_clamps += (c >> 1) & 1;
  }
}

void CpuStepper::check_stability(const World& world, double mechanical_energy) const {
  const Bodies& b = world.bodies;
  bool any_kinematic = false;
  for (std::size_t k = 0; k < b.size(); ++k) {
    any_kinematic |= b.motion[k] == MotionType::Kinematic;
    const bool finite = b.position[k].allFinite() && b.linear_velocity[k].allFinite() &&
                        b.angular_velocity[k].allFinite() && b.orientation[k].coeffs().allFinite();
    if (!finite) {
      throw Error(ExitCode::Unstable, fmt::format("simulation unstable at t = {:.6g} s: body {} has a non-finite "
                                                  "state (reduce dt; see the time-step bound)",
                                                  world.time, k));
    }
  }
  if (!settings_.check_energy || any_kinematic) return;  // kinematic bodies do work on the system
  const double growth = mechanical_energy - energy_reference_;
  if (growth > settings_.energy_growth_tolerance * energy_scale_) {
    throw Error(ExitCode::Unstable,
                fmt::format("simulation unstable at t = {:.6g} s: mechanical energy grew by {:.3g} J with no work "
                            "done (allowed {:.3g} J); reduce dt (see the time-step bound)",
                            world.time, growth, settings_.energy_growth_tolerance * energy_scale_));
  }
}

StepStats CpuStepper::step(World& world) {
  if (world.materials.size() != material_count_) reset_energy_reference(world);
  StepStats stats;
  apply_tracks(world, world.time);  // keyframed bodies start the step on their track
  compute_forces(world, stats);
  if (settings_.tangential == TangentialModel::Spring) std::swap(world.springs, next_springs_);
  // Kinetic + potential + spring energy at the start of the step: what the contacts may only lose.
  const Energy start = energy(world);
  const double mechanical = start.total() + stats.elastic_energy;  // J
  if (reference_pending_) {
    energy_reference_ = mechanical;
    // Allowed growth scale: the energy in motion and springs, plus lifting everything by one
    // diameter and a 1 cm/s stir, so a bed at rest without gravity still has a finite scale.
    energy_scale_ = start.translational + start.rotational + stats.elastic_energy +
                    dynamic_mass_ * (world.gravity.norm() * max_diameter_ + 1e-4);
    reference_pending_ = false;
  }
  integrate(world, stats);
  apply_tracks(world, world.time + settings_.dt);  // and end it there, with the velocities of that time
  world.time += settings_.dt;
  stats.energy = energy(world);
  check_stability(world, mechanical);
  return stats;
}

}  // namespace ts::sim
