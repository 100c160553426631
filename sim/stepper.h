#pragma once
// The one interface of the two DEM engines, and the data every engine takes and gives: the settings
// of a step, the statistics of a step and one contact of a state. sim::CpuStepper
// (sim/cpu_stepper.h, double precision) and sim::GpuStepper (sim/gpu_stepper.h, GL compute) both
// implement Stepper; sim::run_scene (scene/scene_runner.h) drives either through it.
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
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
  // Wall penetration: a dynamic particle whose sphere lies wholly behind a smooth wall's surface (its
  // overlap beyond its diameter) has passed through: the run stops (WallPenetration). Checked every
  // step on both engines.
  bool check_penetration = true;
  // GPU pipeline only: every this many steps the bodies are re-sorted by the cell of their centre
  // (Morton order), so neighbours sit near each other in memory; 0 = never. Results stay
  // deterministic; forces change only by the order of float sums.
  std::int64_t resort_every = 100;
  // Contact candidate lists (sim/contact_lists.h): the skin (m) added to each pair's contact distance
  // when the lists are built; 0 = choose_skin() from the largest diameter, `design_speed` and dt.
  double skin = 0;
  double design_speed = 0;  // m/s: the fastest the scene expects a particle to move (its impact speed)
};

// Dynamic particles found wholly behind a smooth wall's surface (StepSettings::check_penetration).
struct Penetration {
  std::size_t count = 0;       // particle-steps (CPU: of the step; GPU: summed since the last statistics)
  std::uint32_t particle = 0;  // the lowest world id of such a particle
  std::int64_t wall = 0;       // the first smooth wall it passed through (planes, then cylinders)
};

struct StepStats {
  Energy energy;                          // J, after the step
  double elastic_energy = 0;              // J, in the contact springs at the start of the step (CPU reference),
                                          // and in the bonds (sim/bonds.h)
  std::size_t contacts = 0;               // particle pairs in contact (each pair once)
  std::size_t wall_contacts = 0;          // particle-wall contacts
  double max_overlap_ratio = 0;           // largest overlap / smaller radius
  std::size_t velocity_clamps = 0;        // bodies whose linear speed was capped
  std::size_t angular_velocity_clamps = 0;
  std::size_t overlap_clamps = 0;         // contacts whose overlap was capped
  std::size_t spring_overflows = 0;       // contacts beyond a particle's spring slots (no spring: viscous only)
  std::size_t bonds_broken = 0;           // bonds of breakable props broken by the step (summed by advance())
  Penetration penetration;                // when check_penetration is on
};

// A run stopped by a wall penetration (ExitCode::Unstable). The message names the wall by index;
// sim::run_scene replaces it with the scene's names.
class WallPenetration : public Error {
 public:
  WallPenetration(double time, const Penetration& penetration);
  double time() const { return time_; }  // s, when it was found
  const Penetration& penetration() const { return penetration_; }

 private:
  double time_;
  Penetration penetration_;
};

// One contact of the current state, for dumps and tests.
struct ContactRecord {
  std::uint32_t particle = 0;
  std::int64_t partner = 0;      // the other particle, or -1 - wall index (planes first, then cylinders)
  Eigen::Vector3d point;         // m, middle of the overlap
  Eigen::Vector3d force;         // N, on `particle`
  double overlap = 0;            // m
};

// A DEM engine as the scene runner drives it: load a state, advance it, list its contacts.
class Stepper {
 public:
  virtual ~Stepper() = default;
  // Takes `world` as the whole new state (at the start, and after emitters added grains). The
  // energy check's reference is taken again from it.
  virtual void load(const World& world) = 0;
  // Advances `steps` steps of settings().dt and brings `world` up to date. Returns the last step's
  // statistics with the clamp and spring-overflow counts summed over the steps. Throws
  // ts::Error(ExitCode::Unstable) on a blow-up; `world` may then hold the offending state.
  virtual StepStats advance(World& world, std::int64_t steps) = 0;
  // Every contact of `world` (each particle pair once), as the CPU reference computes them.
  virtual std::vector<ContactRecord> contacts(const World& world) = 0;
  // Per-kernel times for --timings; empty where the engine keeps none.
  virtual std::string timing_report() { return {}; }
  virtual const StepSettings& settings() const = 0;

  // For checkpoints (scene/checkpoint.h): which engine this is ("cpu reference", "gpu float", ...; a
  // checkpoint resumes only on the engine that wrote it), and its own state beyond the world it last
  // brought up to date (the GPU's memory order, its re-sort counter, the energy check's reference), so
  // that after load(world) and restore_state(world, save_state()) it steps on bit for bit. Throws
  // ts::InputError when `state` does not belong to `world` or to this engine.
  virtual std::string engine() const = 0;
  virtual std::string save_state() const = 0;
  virtual void restore_state(const World& world, std::string_view state) = 0;
};

}  // namespace ts::sim
