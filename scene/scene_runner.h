#pragma once
// Runs a scene from start to finish: builds the world, settles the time step (auto, or the user's
// with a warning above the bound), releases pour emitters as time passes, steps through a Stepper
// (sim/stepper.h: the CPU reference by default, or the GPU pipeline) and writes the [output] files:
//   metrics.csv                one row per output (energies, contacts, overlap, clamp and spring-slot
//                              overflow counts since the previous row; breakable props' intact and broken
//                              bonds, fragments and the largest fragment's mass)
//   particles_NNNNNN.ply       binary little-endian: float x y z radius, uint body
//   particles_NNNNNN.vtp       VTK XML PolyData, binary (scene/vtk_files.h): a vertex per particle with
//                              radius, body, velocity, angular velocity, orientation, body centre
//   particles.pvd              the .vtp files with their times, for ParaView's time series
//   contacts_NNNNNN.csv        one row per contact (CPU reference: recomputed for the output state)
//   frames                     through the write_frame hook (the preview renderer lives in the app)
//   checkpoint_STEP.tsck       with [output] checkpoint_every / checkpoint_seconds: the complete state
//                              (scene/checkpoint.h), the two latest kept; RunControl::resume goes on from
//                              the latest, bit for bit as if the run had never stopped
// Before the first step the scene's forces are checked (scene/scene_checks.h: exit 1). On an unstable
// step (non-finite state, energy growth, a wall penetration, velocity clamps that do not die out) the
// last good state is written as last_good.ply and a ts::Error (ExitCode::Unstable) thrown.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "scene/scene.h"
#include "sim/stepper.h"
#include "scene/uses_engine.h"

namespace ts::scene {

struct RunHooks {
  // Changes the initial world from the scene before anything else sees it (fresh and resumed runs
  // alike): for benches that need what a scene file cannot say, such as the oedometer's sphere grains.
  // The bodies of the scene's props must keep their indices.
  std::function<void(World& world)> edit_initial_world;
  // Called for each output when [output] frames = true; `frame` counts outputs from 0.
  std::function<void(const World& world, std::int64_t frame, const std::filesystem::path& dir)> write_frame;
  // Called after every output (progress reports, tests).
  std::function<void(const World& world, const StepStats& stats, std::int64_t step)> on_output;
  // Called once with the engine after the last step (e.g. for its --timings report).
  std::function<void(Stepper& stepper)> on_finish;
  // Called after each checkpoint is written (tests stop a run there).
  std::function<void(const std::filesystem::path& file, std::int64_t step)> on_checkpoint;
};

struct RunControl {
  bool resume = false;  // go on from the latest checkpoint in the output folder
  double duration = 0;  // s, overriding the scene's (fresh) or the checkpoint's (resume); 0: theirs
};

// Makes the engine of a run from the settings with dt resolved; the runner loads the world.
using StepperFactory = std::function<std::unique_ptr<Stepper>(const StepSettings& settings)>;

// The bodies of a run's world, counted apart: a dynamic prop is not a grain, a rough wall is a static
// body but not a prop.
struct BodyCounts {
  std::size_t grains = 0;  // the emitters' dynamic grains
  std::size_t dynamic_props = 0, kinematic_props = 0, static_props = 0;
  std::size_t rough_walls = 0;  // static particle bodies of the rough boundaries
  std::size_t smooth_planes = 0, smooth_cylinders = 0;
};
BodyCounts count_bodies(const Scene& scene, const World& world);

// The bonds of a run's breakable props (all zero without one), as metrics.csv and the summary give them.
struct BondCounts {
  std::size_t intact = 0, broken = 0;  // bonds; broken: since the start
  std::size_t fragments = 0;           // groups of spheres intact bonds join (scene/fragments.h)
  double largest_fragment_mass = 0;    // kg
};
BondCounts count_bonds(const Scene& scene, const World& world);
// The same from fragments already found (scene/fragments.h) for this world.
struct Fragments;
BondCounts count_bonds(const World& world, const Fragments& fragments);

// One kind of file a run wrote into its output folder: `pattern` as a user would list it
// ("particles_NNNNNN.ply"), `count` files (or rows, for metrics.csv).
struct OutputRecord {
  std::string pattern;
  std::int64_t count = 0;
  std::string unit;  // "rows", "files" or "entries" (of a collection)
};

struct RunResult {
  std::int64_t steps = 0;
  double dt = 0;                 // s, as used
  std::string time_step_warning; // non-empty when the user's dt exceeds the bound
  StepStats last;
  std::size_t grains = 0;  // grains at the end (dynamic bodies that are not props)
  BodyCounts bodies;       // at the end
  TimeStepBound bound;     // of the scene's contacts and bonds (limiting_bound names the term that set it)
  std::size_t bonds_at_start = 0;  // intact bonds of the initial world (a resumed run: the scene's)
  BondCounts bonds;                // at the end
  std::int64_t outputs = 0;
  std::vector<OutputRecord> files;  // what the output folder holds after the run, checkpoints apart
  // Contacts over the whole run that found no free spring slot (spring tangential model): each ran
  // without static friction for that step.
  std::size_t spring_overflows = 0;
  std::int64_t resumed_from = -1;  // the step a resumed run went on from (-1: a fresh run)
  std::int64_t checkpoints = 0;    // written by this run
};

// The time step a scene runs with: its own, or the recommended bound for "auto".
// `bound_used`, when given, receives the scene's bound.
double resolve_time_step(const Scene& scene, const World& world, std::string* warning,
                         TimeStepBound* bound_used = nullptr);

// `make_stepper` receives the settings with dt filled in (default: the CPU reference).
RunResult run_scene(const Scene& scene, const std::filesystem::path& output_dir, const RunHooks& hooks = {},
                    const StepperFactory& make_stepper = {}, const RunControl& control = {});

// Output writers (atomic), usable on their own (the .vtp writer: scene/vtk_files.h).
void write_particles_ply(const World& world, const std::filesystem::path& file);
void write_contacts_csv(const std::vector<ContactRecord>& contacts, const std::filesystem::path& file);

}  // namespace ts::scene
