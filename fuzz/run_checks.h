#pragma once
// What the scene and checkpoint targets assert about a run that ended at exit 0 (issue 46, item 6):
// nothing non-finite in its state or files, every particle within the grid's documented reach
// (sim/world.h kMaxCellCoordinate cells of the largest particle diameter). A failed check
// prints what broke and aborts, which libFuzzer and fuzz/mutation_driver.cpp both keep as a crash.
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "sim/world.h"

namespace ts::fuzz {

// The run hooks that check the state at every output.
scene::RunHooks checking_hooks();

// Every number in the run's metrics.csv and particle PLYs is finite.
void require_finite_files(const std::filesystem::path& output_dir);

// Runs `scene` on the CPU reference with `control` (a fresh run for at most `max_steps` steps of its
// time step; a resumed one up to control.duration): an input the tool refuses (exit 1) or stops
// (exit 4) is fine; an exit-0 run must pass the checks above; any other error (an internal one,
// exit 5) aborts.
void run_and_check(const scene::Scene& scene, const std::filesystem::path& output_dir, scene::RunControl control,
                   std::int64_t max_steps);

// How the runs of run_and_check ended so far, one line ("N runs: R refused (exit 1), S stopped
// (exit 4), K ran to exit 0 and passed the checks"): fuzz/mutation_driver.cpp prints it at the end
// through the C name TetrasandFuzzSummary, so a pass that never reaches exit 0 shows.
const char* run_summary();

// Prints `what` and aborts: the target's own finding.
[[noreturn]] void fail_check(std::string_view what);

}  // namespace ts::fuzz
