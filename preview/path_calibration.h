#pragma once
// `--gpu-path auto`: the GL renderer makes its shadow map and G-buffer with compute kernels, unless a
// short calibration on this GL renderer and driver found the draws faster (on NVIDIA's GH100 only 4 of
// 132 SMs run graphics shaders; on llvmpipe the draws measured about as fast: docs/benchmarks/preview.md).
// The same per-device choice as the scan conversion's (sdf/scan_calibration.h): timed once per
// renderer, driver and build, cached by gpu/path_calibration.h. See docs/commands/preview.md.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "gpu/context.h"
#include "gpu/path_calibration.h"
#include "preview/compute_passes.h"

namespace ts::preview {

// Environment variable naming the cache file (tests point it into a temporary folder).
inline constexpr const char* kPreviewCacheVariable = "TETRASAND_PREVIEW_CACHE";

// The preview's calibration: "compute" (first, wins ties) against "raster".
const gpu::CalibrationKind& preview_calibration_kind();

// The path a GL preview takes and why, for the `gpu path:` line: "compute (asked for)",
// "raster (calibrated 0.8x raster's speed, cached)".
struct GpuPathChoice {
  GpuPath path = GpuPath::Compute;
  std::string reason;
  std::string describe() const { return std::string(gpu_path_name(path)) + " (" + reason + ")"; }
};

// Times both paths on a built-in scene like a preview's (a sphere's level set with particle impostors
// on a shell around it, with its shadow map: 512^2 pixels on a hardware GPU, 64^2 on a software
// renderer, where the sparse ray cast takes seconds at 256^2), each path twice, alternating, the
// faster run of each; compiling is in the first run. Requires a current context. Measured on llvmpipe:
// docs/benchmarks/preview.md.
gpu::PathTiming calibrate_gpu_path(gpu::Context& context);

// Resolves a --gpu-path: Raster or Compute as asked; Auto by the calibration cached in `cache` (when
// given) for this renderer, driver and build, else by running `calibrate` and caching its result.
GpuPathChoice choose_gpu_path(gpu::Context& context, GpuPath requested,
                              const std::optional<std::filesystem::path>& cache,
                              const std::function<gpu::PathTiming()>& calibrate);
// The same with the cache at gpu::calibration_cache_path(preview_calibration_kind()) and calibrate_gpu_path.
GpuPathChoice choose_gpu_path(gpu::Context& context, GpuPath requested);

}  // namespace ts::preview
