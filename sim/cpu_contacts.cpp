#include "sim/cpu_contacts.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "sim/cpu_parallel.h"

namespace ts::sim {

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

// Each contact is counted once: walls and non-dynamic partners by the dynamic particle (the only
// side that computes them), pairs of dynamic particles by the lower id.
bool counted_here(const World& world, std::uint32_t i, std::int64_t partner) {
  if (partner < 0) return true;
  const auto j = static_cast<std::uint32_t>(partner);
  return world.bodies.inverse_mass[world.particles.body[j]] == 0 || i < j;
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

void CpuContacts::ParticleContacts::add(const ContactForce<double>& c, double smaller_radius, bool count) {
  if (!c.touching) return;
  force += c.force;
  torque += c.arm.cross(c.force);
  if (!count) return;
  max_overlap_ratio = std::max(max_overlap_ratio, c.overlap / smaller_radius);
  elastic_energy += c.elastic_energy;
  overlap_clamps += c.overlap_clamped ? 1 : 0;
}

double CpuContacts::overlap_ratio_cap() const { return settings_.max_overlap_ratio > 0 ? settings_.max_overlap_ratio : 1e30; }

template <typename Fn>
void CpuContacts::visit_contacts(const World& world, std::uint32_t slot, Fn&& fn, SpringSlots* springs) const {
  SpringLookup lookup(springs);
  visit_neighbours(slot, fn, lookup);
  visit_walls(world, slot, fn, lookup);
}

// The particle's list, by increasing partner id: only touching pairs go on to the force (which
// repeats the test with the distance itself).
template <typename Fn>
void CpuContacts::visit_neighbours(std::uint32_t slot, Fn& fn, SpringLookup& lookup) const {
  const double cap = overlap_ratio_cap();
  const ParticleState& me = state_[slot];
  for (const ListEntry& entry : lists_.candidates(slot)) {
    const ParticleState& other = state_[entry.slot];
    const double reach = me.radius + other.radius;  // m
    if ((me.position - other.position).squaredNorm() >= reach * reach) continue;
    const auto& coefficients = pairs_[me.material * material_count_ + other.material];
    const double smaller = std::min(me.radius, other.radius);
    const auto partner = static_cast<std::int64_t>(entry.particle);
    const ContactForce<double> f = sphere_sphere_contact(
        me.position, me.velocity, me.angular_velocity, me.radius, me.inverse_mass, other.position, other.velocity,
        other.angular_velocity, other.radius, other.inverse_mass, cap * smaller, coefficients, settings_.dt,
        lookup.find(partner), lists_.pairs().rest_overlap_of(entry.pair));
    if (!f.touching) continue;
    lookup.keep(partner);
    fn(f, partner, smaller);
  }
}

// The test visit_neighbours makes before the contact law, on the compact copy (the same bits).
bool CpuContacts::spheres_touch(std::uint32_t first_slot, std::uint32_t second_slot) const {
  const Sphere& a = sphere_[first_slot];
  const Sphere& b = sphere_[second_slot];
  const double reach = a.radius + b.radius;  // m
  return !((a.centre - b.centre).squaredNorm() >= reach * reach);
}

bool CpuContacts::pair_contact(const ParticleState& a, const ParticleState& b, double cap, double rest_overlap,
                               PairContact& out) const {
  const auto& coefficients = pairs_[a.material * material_count_ + b.material];
  const ContactForce<double> f =
      sphere_sphere_contact(a.position, a.velocity, a.angular_velocity, a.radius, a.inverse_mass, b.position,
                            b.velocity, b.angular_velocity, b.radius, b.inverse_mass,
                            cap * std::min(a.radius, b.radius), coefficients, settings_.dt,
                            static_cast<Eigen::Vector3d*>(nullptr), rest_overlap);
  if (!f.touching) return false;
  const double smaller = std::min(a.radius, b.radius);  // m
  // The second particle's arm as sphere_sphere_contact forms it (the same operations, so the same bits).
  const Eigen::Vector3d d = a.position - b.position;
  const double distance = d.norm();
  const Eigen::Vector3d arm_second =
      (b.radius - 0.5 * (a.radius + b.radius - distance - rest_overlap)) * (d / distance);
  out = {f.force, f.arm, arm_second, f.overlap / smaller, f.elastic_energy, f.overlap_clamped};
  return true;
}

// Three passes: the touching test on every pair, the touching ones numbered in pair order, the law
// on those alone.
void CpuContacts::compute_pair_contacts() {
  const CandidatePairs& pairs = lists_.pairs();
  const auto count = static_cast<std::uint32_t>(pairs.size());
  const double cap = overlap_ratio_cap();
  contact_of_pair_.resize(count);
  for_each_index(count, [&](std::uint32_t p) {
    contact_of_pair_[p] = spheres_touch(pairs.first[p], pairs.second[p]) ? 0 : kNotTouching;
  });
  touching_pairs_.clear();
  for (std::uint32_t p = 0; p < count; ++p) {
    if (contact_of_pair_[p] == kNotTouching) continue;
    contact_of_pair_[p] = static_cast<std::uint32_t>(touching_pairs_.size());
    touching_pairs_.push_back(p);
  }
  pair_contacts_.resize(touching_pairs_.size());
  for_each_index(static_cast<std::uint32_t>(touching_pairs_.size()), [&](std::uint32_t k) {
    const std::uint32_t p = touching_pairs_[k];
    // A pair whose bond broke touches only past its rest overlap (BondSet::rest_overlap), as on the
    // spring path; 0 for every other pair.
    const double rest = pairs.rest_overlap_of(p);
    if (!pair_contact(state_[pairs.first[p]], state_[pairs.second[p]], cap, rest, pair_contacts_[k])) {
      contact_of_pair_[p] = kNotTouching;
    }
  });
}

// The particle's list by increasing partner id, as visit_neighbours and the gather's ParticleContacts
// updates, but each contact read from its pair: the first side (the one that counts it) takes the force
// as computed, the second its negation about its own arm. The contact law is antisymmetric bit for bit
// (sim/contact_model.h: the difference vectors, the normal and the relative velocity only change sign
// when the two particles swap), so either side sums what computing it from its own side gives.
//
// Written for the branch predictor and the optimiser: about one candidate in five touches, so a test
// and jump per candidate mispredicts often; instead a chunk of the list is first compacted without
// branches (each candidate's place written, the count advanced only by a touching one), then the
// touching ones are summed. The sums stay in locals (the stores into `out` could alias the lists'
// storage and made the compiler reload it each time), and the side a contact is read from picks a
// sign and an arm instead of a branch: -1 * f is -f and adding 0 to a sum changes no bit, so the
// results are the same bits as the plain loop's.
void CpuContacts::add_pair_contacts(std::uint32_t slot, ParticleContacts& out) const {
  const std::span<const ListEntry> list = lists_.candidates(slot);
  const std::uint32_t* contact_of_pair = contact_of_pair_.data();
  const PairContact* contacts = pair_contacts_.data();
  Eigen::Vector3d force = out.force, torque = out.torque;
  double max_overlap_ratio = out.max_overlap_ratio, elastic_energy = out.elastic_energy;
  std::uint32_t touching = 0, pairs = 0, overlap_clamps = 0;
  constexpr std::size_t kChunk = 32;
  std::uint32_t touching_contact[kChunk];
  bool touching_first[kChunk];
  for (std::size_t begin = 0; begin < list.size(); begin += kChunk) {
    const std::size_t end = std::min(list.size(), begin + kChunk);
    std::size_t found = 0;
    for (std::size_t e = begin; e < end; ++e) {
      const std::uint32_t contact = contact_of_pair[list[e].pair];
      touching_contact[found] = contact;
      touching_first[found] = list[e].first;
      found += contact != kNotTouching ? 1 : 0;
    }
    for (std::size_t k = 0; k < found; ++k) {
      const PairContact& c = contacts[touching_contact[k]];
      const bool first = touching_first[k];
      const Eigen::Vector3d f = (first ? 1.0 : -1.0) * c.force;
      force += f;
      torque += (first ? c.arm_first : c.arm_second).cross(f);
      // The statistics are the first side's (it counts the contact).
      max_overlap_ratio = std::max(max_overlap_ratio, first ? c.overlap_ratio : 0.0);
      elastic_energy += first ? c.elastic_energy : 0.0;
      overlap_clamps += first && c.overlap_clamped ? 1 : 0;
      pairs += first ? 1 : 0;
    }
    touching += static_cast<std::uint32_t>(found);
  }
  out.force = force;
  out.torque = torque;
  out.max_overlap_ratio = max_overlap_ratio;
  out.elastic_energy = elastic_energy;
  out.touching += touching;
  out.pairs += pairs;
  out.overlap_clamps += overlap_clamps;
}

// Smooth walls, in declaration order: planes, then cylinders (partner -1 - wall index).
template <typename Fn>
void CpuContacts::visit_walls(const World& world, std::uint32_t slot, Fn& fn, SpringLookup& lookup) const {
  if (!near_wall_[slot]) return;
  const ParticleState& me = state_[slot];
  const double ri = me.radius;
  const Eigen::Vector3d& x = me.position;
  const double max_overlap = overlap_ratio_cap() * ri;
  std::int64_t wall_index = 0;
  auto touch = [&](const Eigen::Vector3d& normal, double gap, std::uint16_t material) {
    const auto& coefficients = pairs_[me.material * material_count_ + material];
    const ContactForce<double> f =
        sphere_wall_contact(normal, gap, me.velocity, me.angular_velocity, ri, me.inverse_mass, max_overlap,
                            coefficients, settings_.dt, lookup.find(-1 - wall_index));
    if (!f.touching) return;
    lookup.keep(-1 - wall_index);
    fn(f, -1 - wall_index, ri);
  };
  for (const PlaneWall& wall : world.walls.planes) {
    const double gap = wall.normal.dot(x - wall.point);
    if (gap < ri) touch(wall.normal, gap, wall.material);
    ++wall_index;
  }
  for (const CylinderWall& wall : world.walls.cylinders) {
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
  // Particle world positions and velocities from the body poses (eqs. 3.42, 3.43), body by body: one
  // rotation matrix a body (a grain has 4 particles) costs less than a quaternion rotation a particle.
  for_each_index(static_cast<std::uint32_t>(b.size()), [&](std::uint32_t k) {
    const Eigen::Matrix3d rotation = b.orientation[k].toRotationMatrix();
    for (std::uint32_t i = b.first_particle[k]; i < b.first_particle[k] + b.particle_count[k]; ++i) {
      const Eigen::Vector3d arm = rotation * p.offset[i];
      position_[i] = b.position[k] + arm;
      velocity_[i] = b.linear_velocity[k] + b.angular_velocity[k].cross(arm);
    }
  });
  const bool build = lists_.stale(position_);
  if (build) {
    const auto start = std::chrono::steady_clock::now();
    lists_.build(world, position_, settings_);
    build_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  // The step's state in cell order: a list's partners sit near their particle in memory.
  state_.resize(n);
  sphere_.resize(n);
  const std::vector<std::uint32_t>& order = lists_.order();
  for_each_index(n, [&](std::uint32_t s) {
    const std::uint32_t i = order[s];
    const std::uint32_t k = p.body[i];
    state_[s] = {position_[i], velocity_[i], b.angular_velocity[k], p.radius[i], b.inverse_mass[k], p.material[i]};
    sphere_[s] = {position_[i], p.radius[i]};
  });
  if (build || near_wall_.size() != n || world.walls.planes != walls_marked_.planes ||
      world.walls.cylinders != walls_marked_.cylinders) {
    mark_near_walls(world);
  }
}

// From the particles' positions now, which are within half the skin of the build's, so a particle
// moves at most a skin from here before the lists go stale: a wall it could touch by then has a gap
// under its radius + the skin. The tests are written so that a NaN marks the particle near (visited,
// as before the marks).
void CpuContacts::mark_near_walls(const World& world) {
  const auto n = static_cast<std::uint32_t>(state_.size());
  near_wall_.resize(n);
  const double skin = lists_.skin();  // m
  for_each_index(n, [&](std::uint32_t s) {
    const Eigen::Vector3d& x = sphere_[s].centre;
    const double reach = sphere_[s].radius + skin;  // m
    bool near = false;
    for (const PlaneWall& wall : world.walls.planes) near |= !(wall.normal.dot(x - wall.point) >= reach);
    for (const CylinderWall& wall : world.walls.cylinders) {
      near |= !(wall.radius - (x.head<2>() - wall.axis).norm() >= reach);
    }
    near_wall_[s] = near ? 1 : 0;
  });
  walls_marked_ = world.walls;
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
        world, lists_.slot(i),
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
  for_each_index(n, [&](std::uint32_t i) {
    if (world.bodies.inverse_mass[world.particles.body[i]] == 0) return;
    SpringSlots slots = read_only_slots(world, i);
    visit_contacts(
        world, lists_.slot(i),
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
  const auto start = std::chrono::steady_clock::now();
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
  particle_contacts_.assign(n, ParticleContacts{});
  overflows_.assign(springs ? n : 0, 0);
  // Without springs each pair's contact is computed once, then summed per particle below; a spring
  // belongs to one side of its pair, so with springs each side computes its own.
  if (!springs) compute_pair_contacts();
  const std::vector<std::uint32_t>& order = lists_.order();
  // In cell order, so that neighbouring particles, and their lists' partners, are visited together.
  for_each_index(n, [&](std::uint32_t s) {
    const std::uint32_t i = order[s];
    ParticleContacts& out = particle_contacts_[i];
    // Static and kinematic particles need no force: their partners compute their own side.
    if (state_[s].inverse_mass == 0) return;
    SpringSlots slots;
    if (springs) {
      if (i < old_particles) {
        slots.old_partner = &world.springs.partner[i * K];
        slots.old_displacement = &world.springs.displacement[i * K];
      }
      slots.new_partner = &out_forces.springs.partner[i * K];
      slots.new_displacement = &out_forces.springs.displacement[i * K];
    }
    auto add = [&](const ContactForce<double>& f, std::int64_t partner, double smaller_radius) {
      const bool wall = partner < 0;
      const bool counted = counted_here(world, i, partner);
      out.add(f, smaller_radius, counted);
      out.pairs += (!wall && counted) ? 1 : 0;
      out.walls += wall ? 1 : 0;
      out.touching += wall ? 0 : 1;
      if (f.passed_through && out.passed_wall < 0) out.passed_wall = -1 - partner;
    };
    if (springs) {
      visit_contacts(world, s, add, &slots);
    } else {
      add_pair_contacts(s, out);
      SpringLookup no_springs(nullptr);
      visit_walls(world, s, add, no_springs);
    }
    if (springs) overflows_[i] = slots.overflows;
  });
  reduce(out_forces, stats);
  ++gathers_;
  gather_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Statistics in world order (so in a fixed order, whatever the cell order and the threads).
void CpuContacts::reduce(GatheredForces& out_forces, StepStats& stats) {
  const std::size_t n = particle_contacts_.size();
  for (std::size_t o : overflows_) stats.spring_overflows += o;
  out_forces.force.resize(n);
  out_forces.torque.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const ParticleContacts& c = particle_contacts_[i];
    out_forces.force[i] = c.force;
    out_forces.torque[i] = c.torque;
    stats.contacts += c.pairs;
    stats.wall_contacts += c.walls;
    stats.overlap_clamps += c.overlap_clamps;
    stats.elastic_energy += c.elastic_energy;
    stats.max_overlap_ratio = std::max(stats.max_overlap_ratio, c.max_overlap_ratio);
    touching_ += c.touching;
    if (!settings_.check_penetration || c.passed_wall < 0 || stats.penetration.count++ > 0) continue;
    // The lowest id that passed through a smooth wall, with its wall.
    stats.penetration.particle = static_cast<std::uint32_t>(i);
    stats.penetration.wall = c.passed_wall;
  }
}

std::string CpuContacts::report() const {
  const CpuContactLists& l = lists_;
  const double diameter = l.largest_diameter();
  const double listed = static_cast<double>(std::max<std::size_t>(l.listed_particles(), 1));
  const double steps = static_cast<double>(std::max<std::size_t>(gathers_, 1));
  return fmt::format(
      "contact lists (CPU reference): skin {:.4g} m ({:.3g} of the largest diameter, {:.4g} m); {} list builds in {} "
      "steps ({:.1f} steps per build)\n"
      "  per particle that takes a force: {:.2f} candidates (last build), {:.2f} touching partners (mean over steps)\n"
      "  time: {:.3f} s in list builds, {:.3f} s in the contact stage in all ({:.3g} s a step)\n",
      l.skin(), diameter > 0 ? l.skin() / diameter : 0.0, diameter, l.builds(), gathers_,
      static_cast<double>(gathers_) / static_cast<double>(std::max<std::size_t>(l.builds(), 1)),
      static_cast<double>(l.candidate_count()) / listed, static_cast<double>(touching_) / (listed * steps),
      build_seconds_, gather_seconds_, gather_seconds_ / steps);
}

}  // namespace ts::sim
