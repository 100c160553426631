#pragma once
// The contact stage of the CPU reference, in double precision: particle positions from the body
// poses, a hashed grid, and for each dynamic particle the forces of its touching partners (other
// bodies' particles, then walls) gathered in a fixed order, TBB-parallel and deterministic. It is
// apart from the stepper (sim/cpu_stepper.h) because both engines need it: sim::CpuStepper gathers
// its forces here, and the GPU pipeline takes from it what only the reference computes (contact
// dumps, the spring energy of a state it is given).
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sim/contact_model.h"
#include "sim/stepper.h"
#include "sim/world.h"

namespace ts::sim {

// The hashed uniform grid: cell = largest particle diameter; a table of next_pow2(max(2 N, 4)) buckets
// filled by counting sort in particle order, so a bucket lists its particles by increasing id.
struct NeighbourGrid {
  double cell_size = 0;                        // m
  std::uint32_t table_size = 0;                // power of two
  std::vector<Eigen::Vector3i> cell;           // per particle
  std::vector<std::uint32_t> bucket_start;     // table_size + 1 entries
  std::vector<std::uint32_t> sorted;           // particle ids grouped by bucket
};
void build_neighbour_grid(const std::vector<Eigen::Vector3d>& positions, double cell_size, NeighbourGrid& grid);
// x + P1 y + P2 z modulo the table (Teschner et al. 2003 with the x factor set to 1): cells next to
// each other along x get consecutive buckets, so a particle's 27 neighbour cells are 9 contiguous
// scans and neighbouring particles read neighbouring memory. (The GPU grid of
// shaders/common/hash_grid.glsl keeps Teschner's XOR hash; the two grids need not agree.)
std::uint32_t hash_cell(const Eigen::Vector3i& cell, std::uint32_t table_size);

// What one gather of a state produces, per particle in world order.
struct GatheredForces {
  std::vector<Eigen::Vector3d> force;   // N, contact force on the particle
  std::vector<Eigen::Vector3d> torque;  // N m, about the particle centre (tangential forces' arms)
  ContactSprings springs;               // the springs advanced by the step (TangentialModel::Spring only)
};

class CpuContacts {
 public:
  explicit CpuContacts(const StepSettings& settings) : settings_(settings) {}

  // Builds the material-pair table; call again when materials were added (it rebuilds only then,
  // unless `force` is set).
  void set_materials(const World& world, bool force = false);

  // One step's contact forces on `world` as it stands: forces, torques and springs into `out`,
  // contact counts, overlap statistics, clamps and elastic energy into `stats`.
  void gather(const World& world, GatheredForces& out, StepStats& stats);

  // Every contact of `world` as it stands (each particle pair once); springs are read, not advanced.
  std::vector<ContactRecord> contacts(const World& world);

  // J: the Hertz energy stored in every contact of `world` (each once), as gather() counts it.
  double elastic_energy(const World& world);

  // Of the state last gathered or listed: particle world positions (m) and the grid.
  const std::vector<Eigen::Vector3d>& positions() const { return position_; }
  const NeighbourGrid& grid() const { return grid_; }

 private:
  // What the neighbour search reads of each candidate, in the grid's bucket order: one cache line
  // per candidate instead of four scattered loads (the search is most of a step's time).
  struct Candidate {
    Eigen::Vector3d position;  // m
    double radius = 0;         // m
    double inverse_mass = 0;   // 1/kg, of its body
    Eigen::Vector3i cell;
    std::uint32_t body = 0, particle = 0;
  };
  // Particle i's spring slots: the old ones it reads and, when stepping, the new ones it writes.
  struct SpringSlots {
    const std::int64_t* old_partner = nullptr;
    const Eigen::Vector3d* old_displacement = nullptr;
    std::int64_t* new_partner = nullptr;
    Eigen::Vector3d* new_displacement = nullptr;
    std::size_t used = 0, overflows = 0;
  };

  void prepare_particles(const World& world);
  // Calls fn(force, partner, smaller radius) for each touching partner of particle i, in a fixed order.
  // With springs (TangentialModel::Spring) each touching contact takes its spring from `springs`'
  // old slots and, when its new slots are given, writes it back there, advanced.
  template <typename Fn>
  void visit_contacts(const World& world, std::uint32_t i, Fn&& fn, SpringSlots* springs = nullptr) const;
  class SpringLookup;
  template <typename Fn>
  void visit_neighbours(const World& world, std::uint32_t i, Fn& fn, SpringLookup& lookup) const;
  template <typename Fn>
  void visit_walls(const World& world, std::uint32_t i, Fn& fn, SpringLookup& lookup) const;
  double overlap_ratio_cap() const;  // settings' max_overlap_ratio, or no cap
  // Slots of particle i for reading the springs of `world` (none without the spring model).
  SpringSlots read_only_slots(const World& world, std::uint32_t i) const;

  StepSettings settings_;
  std::size_t material_count_ = 0;
  std::vector<ContactCoefficients<double>> pairs_;  // material_count^2, row-major
  NeighbourGrid grid_;
  std::vector<Candidate> candidates_;
  std::vector<Eigen::Vector3d> position_, velocity_;  // per particle, reused between steps
};

}  // namespace ts::sim
