#include "sim/cpu_contacts.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>

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

void CpuContacts::set_materials(const World& world, bool force) {
  if (!force && world.materials.size() == material_count_) return;
  material_count_ = world.materials.size();
  pairs_.clear();
  for (const Material& a : world.materials) {
    for (const Material& b : world.materials) {
      const PairCoefficients p = make_pair_coefficients(a, b, settings_.normal_damping, settings_.thesis_reference_speed);
      pairs_.push_back(ContactCoefficients<double>::from(p, settings_.normal_damping));
    }
  }
}

namespace {

// Everything one particle's gather produces.
struct ParticleContacts {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   // N
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  // N m, about the particle centre
  std::uint32_t pairs = 0, walls = 0, overlap_clamps = 0;
  double max_overlap_ratio = 0;
  double elastic_energy = 0;  // J
  // The first smooth wall (in visiting order) the particle has passed through; -1: none.
  std::int64_t passed_wall = -1;

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

// How many particles passed through a smooth wall in this gather, and the lowest id among them with
// its wall.
void note_penetrations(const std::vector<ParticleContacts>& contacts, Penetration& out) {
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    if (contacts[i].passed_wall < 0 || out.count++ > 0) continue;
    out.particle = static_cast<std::uint32_t>(i);
    out.wall = contacts[i].passed_wall;
  }
}

double max_radius(const World& world) {
  double r = 0;
  for (double x : world.particles.radius) r = std::max(r, x);
  return r;
}

}  // namespace

// The spring of the contact being visited: found in a particle's old slots (zero for a new contact)
// and, when stepping, kept in its new ones. Without springs find() gives null (viscous friction only).
class CpuContacts::SpringLookup {
 public:
  explicit SpringLookup(SpringSlots* slots) : slots_(slots) {}
  Eigen::Vector3d* find(std::int64_t partner) {
    if (!slots_) return nullptr;
    spring_.setZero();
    for (std::size_t k = 0; k < ContactSprings::kSlots && slots_->old_partner; ++k) {
      if (slots_->old_partner[k] == partner) spring_ = slots_->old_displacement[k];
    }
    return &spring_;
  }
  // After a touching contact: its spring, as the force left it, into the next free new slot.
  void keep(std::int64_t partner) {
    if (!slots_ || !slots_->new_partner) return;
    if (slots_->used == ContactSprings::kSlots) {
      ++slots_->overflows;
      return;
    }
    slots_->new_partner[slots_->used] = partner;
    slots_->new_displacement[slots_->used] = spring_;
    ++slots_->used;
  }

 private:
  SpringSlots* slots_;
  Eigen::Vector3d spring_ = Eigen::Vector3d::Zero();
};

double CpuContacts::overlap_ratio_cap() const { return settings_.max_overlap_ratio > 0 ? settings_.max_overlap_ratio : 1e30; }

template <typename Fn>
void CpuContacts::visit_contacts(const World& world, std::uint32_t i, Fn&& fn, SpringSlots* springs) const {
  SpringLookup lookup(springs);
  visit_neighbours(world, i, fn, lookup);
  visit_walls(world, i, fn, lookup);
}

// Other bodies' particles in the 27 cells around, row by row (dz, dy), each row's three cells in
// increasing x and each bucket in increasing id. A row is three consecutive buckets (see hash_cell),
// so it is one contiguous scan unless it wraps around the table's end.
template <typename Fn>
void CpuContacts::visit_neighbours(const World& world, std::uint32_t i, Fn& fn, SpringLookup& lookup) const {
  const Bodies& b = world.bodies;
  const Particles& p = world.particles;
  const double cap = overlap_ratio_cap();
  const std::uint32_t bi = p.body[i];
  const double ri = p.radius[i];
  const double inverse_mass_i = b.inverse_mass[bi];
  const Eigen::Vector3d& xi = position_[i];
  const Eigen::Vector3d& wi = b.angular_velocity[bi];
  const Eigen::Vector3i& own_cell = grid_.cell[i];
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
          b.inverse_mass[bj], cap * smaller, coefficients, settings_.dt, lookup.find(partner));
      if (!f.touching) continue;
      lookup.keep(partner);
      fn(f, partner, smaller);
    }
  };
  const std::uint32_t last_bucket = grid_.table_size - 1;
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
}

// Smooth walls, in declaration order: planes, then cylinders (partner -1 - wall index).
template <typename Fn>
void CpuContacts::visit_walls(const World& world, std::uint32_t i, Fn& fn, SpringLookup& lookup) const {
  const Particles& p = world.particles;
  const std::uint32_t bi = p.body[i];
  const double ri = p.radius[i];
  const Eigen::Vector3d& wi = world.bodies.angular_velocity[bi];
  const double inverse_mass = world.bodies.inverse_mass[bi];
  const double max_overlap = overlap_ratio_cap() * ri;
  std::int64_t wall_index = 0;
  auto touch = [&](const Eigen::Vector3d& normal, double gap, std::uint16_t material) {
    const auto& coefficients = pairs_[p.material[i] * material_count_ + material];
    const ContactForce<double> f = sphere_wall_contact(normal, gap, velocity_[i], wi, ri, inverse_mass, max_overlap,
                                                       coefficients, settings_.dt, lookup.find(-1 - wall_index));
    if (!f.touching) return;
    lookup.keep(-1 - wall_index);
    fn(f, -1 - wall_index, ri);
  };
  for (const PlaneWall& wall : world.walls.planes) {
    const double gap = wall.normal.dot(position_[i] - wall.point);
    if (gap < ri) touch(wall.normal, gap, wall.material);
    ++wall_index;
  }
  for (const CylinderWall& wall : world.walls.cylinders) {
    const Eigen::Vector3d& x = position_[i];
    const Eigen::Vector2d radial = x.head<2>() - wall.axis;
    const double distance = radial.norm();
    if (x.z() >= wall.z_min && x.z() <= wall.z_max && distance > 0) {
      touch(Eigen::Vector3d(-radial.x() / distance, -radial.y() / distance, 0.0), wall.radius - distance, wall.material);
    }
    ++wall_index;
  }
}

void CpuContacts::prepare_particles(const World& world) {
  const Bodies& b = world.bodies;
  const Particles& p = world.particles;
  const auto n = static_cast<std::uint32_t>(p.size());
  position_.resize(n);
  velocity_.resize(n);
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

CpuContacts::SpringSlots CpuContacts::read_only_slots(const World& world, std::uint32_t i) const {
  SpringSlots slots;
  if (settings_.tangential == TangentialModel::Spring &&
      world.springs.partner.size() >= (i + 1) * ContactSprings::kSlots) {
    slots.old_partner = &world.springs.partner[i * ContactSprings::kSlots];
    slots.old_displacement = &world.springs.displacement[i * ContactSprings::kSlots];
  }
  return slots;
}

std::vector<ContactRecord> CpuContacts::contacts(const World& world) {
  set_materials(world);
  prepare_particles(world);
  std::vector<ContactRecord> records;
  for (std::uint32_t i = 0; i < world.particles.size(); ++i) {
    if (world.bodies.inverse_mass[world.particles.body[i]] == 0) continue;
    // Springs are read (the forces include them) but not advanced.
    SpringSlots slots = read_only_slots(world, i);
    visit_contacts(
        world, i,
        [&](const ContactForce<double>& f, std::int64_t partner, double) {
          if (!counted_here(world, i, partner)) return;
          records.push_back({i, partner, position_[i] + f.arm, f.force, f.overlap});
        },
        slots.old_partner ? &slots : nullptr);
  }
  return records;
}

double CpuContacts::elastic_energy(const World& world) {
  set_materials(world);
  prepare_particles(world);
  const auto n = static_cast<std::uint32_t>(world.particles.size());
  std::vector<double> energy(n, 0.0);
  tbb::parallel_for(std::uint32_t{0}, n, [&](std::uint32_t i) {
    if (world.bodies.inverse_mass[world.particles.body[i]] == 0) return;
    SpringSlots slots = read_only_slots(world, i);
    visit_contacts(
        world, i,
        [&](const ContactForce<double>& f, std::int64_t partner, double) {
          if (counted_here(world, i, partner)) energy[i] += f.elastic_energy;
        },
        slots.old_partner ? &slots : nullptr);
  });
  double total = 0.0;  // in particle order, as gather() sums it
  for (double e : energy) total += e;
  return total;
}

void CpuContacts::gather(const World& world, GatheredForces& out_forces, StepStats& stats) {
  prepare_particles(world);
  const auto n = static_cast<std::uint32_t>(world.particles.size());

  const bool springs = settings_.tangential == TangentialModel::Spring;
  constexpr std::size_t K = ContactSprings::kSlots;
  // Each particle reads only its own old slots and writes only its own new ones: thread-safe. Grains
  // appended since the last step (emitters) have no slots yet; everyone else keeps theirs.
  const std::size_t old_particles = world.springs.partner.size() / K;
  if (springs) {
    out_forces.springs.partner.assign(std::size_t{n} * K, ContactSprings::kNoPartner);
    out_forces.springs.displacement.assign(std::size_t{n} * K, Eigen::Vector3d::Zero());
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
      slots.new_partner = &out_forces.springs.partner[i * K];
      slots.new_displacement = &out_forces.springs.displacement[i * K];
    }
    visit_contacts(
        world, i,
        [&](const ContactForce<double>& f, std::int64_t partner, double smaller_radius) {
          const bool wall = partner < 0;
          const bool counted = counted_here(world, i, partner);
          out.add(f, smaller_radius, counted);
          out.pairs += (!wall && counted) ? 1 : 0;
          out.walls += wall ? 1 : 0;
          if (f.passed_through && out.passed_wall < 0) out.passed_wall = -1 - partner;
        },
        springs ? &slots : nullptr);
    if (springs) overflows[i] = slots.overflows;
  });
  for (std::size_t o : overflows) stats.spring_overflows += o;

  // Statistics in particle order.
  out_forces.force.resize(n);
  out_forces.torque.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    out_forces.force[i] = contacts[i].force;
    out_forces.torque[i] = contacts[i].torque;
    stats.contacts += contacts[i].pairs;
    stats.wall_contacts += contacts[i].walls;
    stats.overlap_clamps += contacts[i].overlap_clamps;
    stats.elastic_energy += contacts[i].elastic_energy;
    stats.max_overlap_ratio = std::max(stats.max_overlap_ratio, contacts[i].max_overlap_ratio);
  }
  if (settings_.check_penetration) note_penetrations(contacts, stats.penetration);
}

}  // namespace ts::sim
