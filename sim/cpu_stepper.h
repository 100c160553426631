#pragma once
// The CPU reference stepper: one time step of the DEM in double precision, TBB-parallel and
// deterministic (every sum visits its terms in a fixed order, whatever the thread count). The GPU
// pipeline follows the same stages on the same data layout:
//   poses -> particle positions/velocities -> contact candidate lists with a skin (rebuilt from a
//   hashed grid only when some particle moved more than half the skin) -> per-particle contact force
//   and torque (gather, in cell order: other bodies' particles by increasing id, then walls) ->
//   per-body sums -> integration.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sim/cpu_contacts.h"
#include "sim/stepper.h"
#include "sim/world.h"

namespace ts::sim {

// The CPU reference engine: the contact stage of sim/cpu_contacts.h, then per-body sums and
// integration (forward or symplectic Euler, quaternion orientations), then the stability check.
class CpuStepper : public Stepper {
 public:
  explicit CpuStepper(const StepSettings& settings);
  // The same, loaded with `world` (precomputes the material-pair table; the energy reference is
  // taken from `world` at the first step).
  CpuStepper(const World& world, const StepSettings& settings);

  void load(const World& world) override;
  StepStats advance(World& world, std::int64_t steps) override;
  std::vector<ContactRecord> contacts(const World& world) override;
  const StepSettings& settings() const override { return settings_; }
  std::string engine() const override { return "cpu reference"; }
  std::string save_state() const override;
  void restore_state(const World& world, std::string_view state) override;

  // Advances `world` by settings.dt. Throws ts::Error (ExitCode::Unstable) on NaN/inf, on a wall
  // penetration (WallPenetration) or on energy growth without work; `world` then holds the offending
  // state.
  StepStats step(World& world);

  // Call after doing work on the system (adding grains, moving props by hand): the energy check
  // restarts from the next step's state. Also rebuilds the pair table if materials were added.
  void reset_energy_reference(const World& world);

  // The skin, list builds, candidates and contacts per particle, and the time they took.
  std::string timing_report() override { return contacts_.report(); }

  const CpuContactLists& lists() const { return contacts_.lists(); }

 private:
  // As step(world); the energy after the step (stats.energy) only if `energy_after`, else zero.
  StepStats step_once(World& world, bool energy_after);
  void add_bonds(World& world, StepStats& stats);
  void integrate(World& world, StepStats& stats);
  void check_stability(const World& world, double mechanical_energy, const StepStats& stats) const;

  StepSettings settings_;
  CpuContacts contacts_;
  GatheredForces forces_;           // of the current step; its springs are swapped into the world
  std::vector<std::uint8_t> clamped_;  // per body, of the current step (reused: a step allocates nothing)
  std::size_t material_count_ = 0;  // of the world the energy reference belongs to
  double energy_reference_ = 0;     // J: kinetic + potential + spring energy when the reference was taken
  double energy_scale_ = 0;         // J
  double dynamic_mass_ = 0;         // kg
  double max_diameter_ = 0;         // m
  bool reference_pending_ = true;
};

}  // namespace ts::sim
