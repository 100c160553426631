#pragma once
// `--scan auto`: the compute scan conversion, unless a short calibration on this GL renderer and
// driver found the geometry-shader path faster. The calibration (both paths on a small built-in
// mesh) runs once per renderer, driver and tetrasand build; its result is cached in a JSON file, so
// later runs only read it. A cache that cannot be read, does not parse or holds another renderer's or
// build's entry is ignored (with a warning when it is unreadable), never fatal. See
// docs/commands/sdf.md.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "gpu/context.h"
#include "sdf/settings.h"

namespace ts::sdf {

// Environment variable naming the cache file (tests point it into a temporary folder).
inline constexpr const char* kScanCacheVariable = "TETRASAND_SCAN_CACHE";

// The seconds each path took on the calibration mesh (the faster of two runs each).
struct ScanTiming {
  double compute_seconds = 0.0, geometry_seconds = 0.0;
};

// The method a run uses and why, for the `device:` line: "scan compute (--scan)", "scan compute
// (calibrated 1.3x geometry's speed)", "scan geometry (calibrated 0.8x geometry's speed, cached)".
struct ScanChoice {
  ScanMethod method = ScanMethod::Compute;
  std::string reason;
  std::string describe() const {
    return std::string("scan ") + scan_method_name(method) + " (" + reason + ")";
  }
};

// The running executable's identity (its size and modification time; "unknown" where the system does
// not tell): an entry timed by another build is not used, so a rebuilt or upgraded tetrasand, whose
// scan paths may run at other speeds, times them again.
std::string scan_build_id();

// $TETRASAND_SCAN_CACHE, else $XDG_CACHE_HOME/tetrasand/scan_calibration.json, else
// $HOME/.cache/tetrasand/scan_calibration.json; nullopt when none of them is set (nothing cached).
std::optional<std::filesystem::path> scan_cache_path();

// Times both paths on a built-in icosphere (5120 triangles, 48 voxels along its diameter): tens of
// milliseconds expected on a GPU (not measured yet), seconds on llvmpipe (3.5 to 10 s with compiling,
// on 2 shared cores). Requires a current context.
ScanTiming calibrate_scan(gpu::Context& context);

// Resolves a --scan spelling ("compute", "geometry", "auto"). Auto reads the entry for this context's
// renderer and driver from `cache` (when given), else calls `calibrate` and stores its result there
// (written atomically; a failed write is a warning). Compute wins ties.
ScanChoice choose_scan(gpu::Context& context, std::string_view requested,
                       const std::optional<std::filesystem::path>& cache,
                       const std::function<ScanTiming()>& calibrate);
// The same with scan_cache_path() and calibrate_scan.
ScanChoice choose_scan(gpu::Context& context, std::string_view requested);

}  // namespace ts::sdf
