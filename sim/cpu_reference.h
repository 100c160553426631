#pragma once
// The CPU reference stepper: one time step of the DEM in double precision, TBB-parallel and
// deterministic (every sum visits its terms in a fixed order, whatever the thread count). The GPU
// pipeline follows the same stages on the same data layout:
//   poses -> particle positions/velocities -> hashed grid (counting sort) -> per-particle contact
//   force and torque (gather, other bodies only, then walls) -> per-body sums -> integration.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sim/contact_model.h"
#include "sim/world.h"

namespace ts::sim {

enum class Integrator {
  ForwardEuler,       // thesis eqs. 3.44-3.50: positions and orientations advance with the old velocities
  SemiImplicitEuler,  // symplectic: velocities first, then positions/orientations with the new ones
};

// The tangential force law.
enum class TangentialModel {
  Viscous,  // thesis eq. 3.28: viscous, capped at mu F_n; no static friction, so heaps creep slowly
  Spring,   // elastic spring per contact plus the viscous term, capped (static friction)
};

struct StepSettings {
  double dt = 1e-5;  // s
  NormalDamping normal_damping = NormalDamping::Tsuji;
  TangentialModel tangential = TangentialModel::Viscous;
  double thesis_reference_speed = 1.0;  // m/s: where the thesis damping gives exactly the restitution
  Integrator integrator = Integrator::ForwardEuler;
  // Velocity clamp (thesis 3.3.1, CFL): no particle may move more than `cfl` grid cells in a step;
  // the body's linear speed and its angular speed times its bounding radius are capped at
  // cfl * cell / dt. <= 0 disables it.
  double cfl = 0.5;
  // Overlap clamp: the overlap entering the force is capped at this fraction of the smaller
  // radius, bounding the force after a bad step. <= 0 disables it.
  double max_overlap_ratio = 0.5;
  // Optional low-speed angular damping (off when rate = 0): a body whose fastest point moves slower
  // than `angular_damping_speed` (m/s) has its angular velocity scaled by (1 - rate dt), rate 1/s.
  double angular_damping_rate = 0;
  double angular_damping_speed = 0;
  // Blow-up detection: the mechanical energy (kinetic + potential + contact springs, at the start of
  // each step) may not exceed its value at the first step by more than this fraction of (kinetic +
  // spring energy then + M |g| d_max) while no work is done on the system.
  bool check_energy = true;
  double energy_growth_tolerance = 0.5;
  // GPU pipeline only: every this many steps the bodies are re-sorted by the cell of their centre
  // (Morton order), so neighbours sit near each other in memory; 0 = never. Results stay
  // deterministic; forces change only by the order of float sums.
  std::int64_t resort_every = 100;
};

struct StepStats {
  Energy energy;                          // J, after the step
  double elastic_energy = 0;              // J, in the contact springs at the start of the step
  std::size_t contacts = 0;               // particle pairs in contact (each pair once)
  std::size_t wall_contacts = 0;          // particle-wall contacts
  double max_overlap_ratio = 0;           // largest overlap / smaller radius
  std::size_t velocity_clamps = 0;        // bodies whose linear speed was capped
  std::size_t angular_velocity_clamps = 0;
  std::size_t overlap_clamps = 0;         // contacts whose overlap was capped
  std::size_t spring_overflows = 0;       // contacts beyond a particle's spring slots (no spring: viscous only)
};

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

// One contact of the current state, for dumps and tests.
struct ContactRecord {
  std::uint32_t particle = 0;
  std::int64_t partner = 0;      // the other particle, or -1 - wall index (planes first, then cylinders)
  Eigen::Vector3d point;         // m, middle of the overlap
  Eigen::Vector3d force;         // N, on `particle`
  double overlap = 0;            // m
};

class CpuStepper {
 public:
  // Precomputes the material-pair table; the energy reference is taken from `world`.
  CpuStepper(const World& world, const StepSettings& settings);

  // Advances `world` by settings.dt. Throws ts::Error (ExitCode::Unstable) on NaN/inf or on energy
  // growth without work; `world` then holds the offending state.
  StepStats step(World& world);

  // Call after doing work on the system (adding grains, moving props by hand): the energy check
  // restarts from the next step's state. Also rebuilds the pair table if materials were added.
  void reset_energy_reference(const World& world);

  // Every contact of `world` as it stands (each particle pair once); off the stepping path.
  std::vector<ContactRecord> contacts(const World& world);

  const StepSettings& settings() const { return settings_; }
  const NeighbourGrid& grid() const { return grid_; }

 private:
  void prepare_particles(const World& world);
  // Calls fn(force, partner, smaller radius) for each touching partner of particle i, in a fixed order.
  // With springs (TangentialModel::Spring) each touching contact takes its spring from `old_slots`
  // (particle i's kSlots) and, when `new_slots` is given, writes it back there, advanced.
  struct SpringSlots {
    const std::int64_t* old_partner = nullptr;
    const Eigen::Vector3d* old_displacement = nullptr;
    std::int64_t* new_partner = nullptr;
    Eigen::Vector3d* new_displacement = nullptr;
    std::size_t used = 0, overflows = 0;
  };
  template <typename Fn>
  void visit_contacts(const World& world, std::uint32_t i, Fn&& fn, SpringSlots* springs = nullptr) const;
  void compute_forces(const World& world, StepStats& stats);
  void integrate(World& world, StepStats& stats) const;
  void check_stability(const World& world, double mechanical_energy) const;

  StepSettings settings_;
  std::size_t material_count_ = 0;
  std::vector<ContactCoefficients<double>> pairs_;  // material_count^2, row-major
  NeighbourGrid grid_;
  // What the neighbour search reads of each candidate, in the grid's bucket order: one cache line
  // per candidate instead of four scattered loads (the search is most of a step's time).
  struct Candidate {
    Eigen::Vector3d position;  // m
    double radius = 0;         // m
    double inverse_mass = 0;   // 1/kg, of its body
    Eigen::Vector3i cell;
    std::uint32_t body = 0, particle = 0;
  };
  std::vector<Candidate> candidates_;
  // Per-particle scratch, reused between steps.
  std::vector<Eigen::Vector3d> position_, velocity_, force_, torque_;
  ContactSprings next_springs_;  // written by compute_forces, swapped into the world by step()
  double energy_reference_ = 0;  // J: kinetic + potential + spring energy when the reference was taken
  double energy_scale_ = 0;      // J
  double dynamic_mass_ = 0;      // kg
  double max_diameter_ = 0;      // m
  bool reference_pending_ = true;
};

}  // namespace ts::sim
