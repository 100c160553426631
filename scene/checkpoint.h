#pragma once
// Checkpoints of a scene run: the complete state at a step (world, engine, emitters, outputs so far),
// in one versioned binary file per checkpoint, checkpoint_STEP.tsck in the output folder, written
// atomically (docs/checkpoint-format.md). sim::run_scene writes them ([output] checkpoint_every,
// checkpoint_seconds) and resumes from the latest (`tetrasand sim SCENE --resume DIR`).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/scene_checks.h"
#include "scene/scene_world.h"
#include "sim/state_bytes.h"
#include "sim/stepper.h"
#include "sim/world.h"
#include "sim/world_bytes.h"
#include "scene/uses_engine.h"

namespace ts::scene {

inline constexpr std::uint32_t kCheckpointVersion = 3;

// Everything a run needs to go on as if it had never stopped.
struct RunState {
  std::string scene_hash;        // scene_hash() of the scene it belongs to
  std::string engine;            // Stepper::engine()
  double duration = 0;           // s, the run's (the scene's, or --duration)
  double dt = 0;                 // s
  std::int64_t step = 0;         // steps done
  std::int64_t stretch_end = 0;  // where the stretch in progress ends (emitters release at stretch starts)
  std::int64_t stretch_output =
      0;                    // the output step of that stretch (an output is written when it ends there)
  std::int64_t frames = 0;  // outputs written so far
  std::int64_t last_output_step = 0;  // step of the latest output
  // Counts since the latest output, and over the run.
  std::uint64_t velocity_clamps = 0, angular_clamps = 0, overlap_clamps = 0, spring_overflows = 0;
  std::uint64_t run_spring_overflows = 0;
  ClampWatch::State clamp_watch;
  StepStats last;                   // of the latest step
  std::vector<PourProgress> pours;  // one per pour emitter, in scene order
  std::string metrics_csv;          // metrics.csv as written so far
  World world;
  std::string engine_state;  // Stepper::save_state()
};

// SHA-256 (hex) of the scene file's bytes and of the initial world it builds (props' particles and
// mass properties included), so a checkpoint refuses a scene or body that changed.
std::string scene_hash(const Scene& scene, const World& initial_world);

// dir/checkpoint_STEP.tsck (STEP in 12 digits).
std::filesystem::path checkpoint_path(const std::filesystem::path& dir, std::int64_t step);

// Writes the state atomically as checkpoint_path(dir, state.step), then removes all but the
// `keep` latest checkpoints and the temporary files of checkpoints whose writer died.
void write_checkpoint(const std::filesystem::path& dir, const RunState& state, std::size_t keep = 2);

// Reads the latest checkpoint in `dir` (*file: its path). Throws ts::InputError naming the folder
// (missing, no checkpoint) or the file (truncated, corrupt, another format version).
RunState read_latest_checkpoint(const std::filesystem::path& dir, std::filesystem::path* file = nullptr);

// Removes every checkpoint in `dir` (a fresh run replaces the folder's outputs, its checkpoints too),
// and the stale temporary files there.
void remove_checkpoints(const std::filesystem::path& dir);

}  // namespace ts::scene
