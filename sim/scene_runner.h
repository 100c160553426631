#pragma once
// Runs a scene from start to finish: builds the world, settles the time step (auto, or the user's
// with a warning above the bound), releases pour emitters as time passes, steps through a Stepper
// (the CPU reference here; the GPU pipeline through an adapter) and writes the [output] files:
//   metrics.csv                one row per output (energies, contacts, overlap, clamp and spring-slot
//                              overflow counts since the previous row)
//   particles_NNNNNN.ply       binary little-endian: float x y z radius, uint body
//   particles_NNNNNN.vtp       VTK XML PolyData (ASCII): points, radius and body per particle
//   contacts_NNNNNN.csv        one row per contact (CPU reference: recomputed for the output state)
//   frames                     through the write_frame hook (the preview renderer lives in the app)
// On an unstable step the last good state is written as last_good.ply and the ts::Error rethrown.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "sim/cpu_reference.h"
#include "sim/scene.h"

namespace ts::sim {

// The stepping engine the runner drives.
class Stepper {
 public:
  virtual ~Stepper() = default;
  // Takes `world` as the whole new state (at start and after emitters added grains).
  virtual void load(const World& world) = 0;
  // Advances `steps` steps and brings `world` up to date. Returns the last step's statistics with
  // the clamp counts summed over the steps. Throws ts::Error(ExitCode::Unstable) on a blow-up.
  virtual StepStats advance(World& world, std::int64_t steps) = 0;
  // The contacts of the state last loaded or advanced to; empty when the engine cannot list them.
  virtual std::vector<ContactRecord> contacts(const World& world) = 0;
};

class CpuReferenceStepper : public Stepper {
 public:
  explicit CpuReferenceStepper(const StepSettings& settings) : settings_(settings) {}
  void load(const World& world) override;
  StepStats advance(World& world, std::int64_t steps) override;
  std::vector<ContactRecord> contacts(const World& world) override;

 private:
  StepSettings settings_;
  std::unique_ptr<CpuStepper> stepper_;
};

struct RunHooks {
  // Called for each output when [output] frames = true; `frame` counts outputs from 0.
  std::function<void(const World& world, std::int64_t frame, const std::filesystem::path& dir)> write_frame;
  // Called after every output (progress reports, tests).
  std::function<void(const World& world, const StepStats& stats, std::int64_t step)> on_output;
};

struct RunResult {
  std::int64_t steps = 0;
  double dt = 0;                 // s, as used
  std::string time_step_warning; // non-empty when the user's dt exceeds the bound
  StepStats last;
  std::size_t grains = 0;        // dynamic bodies at the end
  std::int64_t outputs = 0;
  // Contacts over the whole run that found no free spring slot (spring tangential model): each ran
  // without static friction for that step.
  std::size_t spring_overflows = 0;
};

// The time step a scene runs with: its own, or the recommended bound for "auto".
double resolve_time_step(const Scene& scene, const World& world, std::string* warning);

// `make_stepper` receives the settings with dt filled in (default: the CPU reference).
RunResult run_scene(const Scene& scene, const std::filesystem::path& output_dir, const RunHooks& hooks = {},
                    const std::function<std::unique_ptr<Stepper>(const StepSettings&)>& make_stepper = {});

// Output writers (atomic), usable on their own.
void write_particles_ply(const World& world, const std::filesystem::path& file);
void write_particles_vtp(const World& world, const std::filesystem::path& file);
void write_contacts_csv(const std::vector<ContactRecord>& contacts, const std::filesystem::path& file);

}  // namespace ts::sim
