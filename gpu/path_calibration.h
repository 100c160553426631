#pragma once
// A per-device choice between two GPU paths of one stage (the scan conversion's compute kernels or
// geometry shader, the preview's compute kernels or draws): both timed once on a small built-in job
// per GL renderer, driver and tetrasand build, the result cached in a JSON file so later runs only
// read it. A cache that cannot be read, does not parse or holds another renderer's or build's entry
// is ignored (with a warning when it is unreadable), never fatal. A device keeps the entries of its
// newest 4 builds, since several executables may share one cache (the tool and a test program). The stages own their calibration
// jobs (sdf/scan_calibration.h, preview/path_calibration.h); this file owns the cache and the rule.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "gpu/context.h"

namespace ts::gpu {

// What a stage's calibration is called and where it is kept. The cache file's format line is
// "tetrasand STAGE calibration 1" and its entries hold FIRST_seconds and SECOND_seconds.
struct CalibrationKind {
  std::string stage;           // "scan", "preview": in the file name, the format line and messages
  std::string cache_variable;  // environment variable naming the cache file (tests point it elsewhere)
  std::string first, second;   // the two paths, as their options spell them; `first` wins ties
};

// The seconds each path took on the calibration job (the faster of two runs each).
struct PathTiming {
  double first_seconds = 0.0, second_seconds = 0.0;
};

// The path a run takes and why: "calibrated 2x geometry's speed" or "..., cached".
struct PathChoice {
  bool first = true;
  std::string reason;
};

// The running executable's identity (its size and modification time; "unknown" where the system does
// not tell): an entry timed by another build is not used, so a rebuilt or upgraded tetrasand, whose
// paths may run at other speeds, times them again.
std::string build_id();

// $CACHE_VARIABLE, else $XDG_CACHE_HOME/tetrasand/STAGE_calibration.json, else
// $HOME/.cache/tetrasand/STAGE_calibration.json; nullopt when none of them is set (nothing cached).
std::optional<std::filesystem::path> calibration_cache_path(const CalibrationKind& kind);

// Reads the entry for this context's renderer and driver and this build from `cache` (when given),
// else calls `calibrate` (logging that it does) and stores its result there, written atomically; a
// failed write is a warning. A calibration that timed nothing (a time not above 0) picks `first`.
PathChoice choose_calibrated_path(const Context& context, const CalibrationKind& kind,
                                  const std::optional<std::filesystem::path>& cache,
                                  const std::function<PathTiming()>& calibrate);

}  // namespace ts::gpu
