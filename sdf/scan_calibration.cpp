#include "sdf/scan_calibration.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/error.h"
#include "core/mesh.h"
#include "core/primitives.h"
#include "gpu/path_calibration.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"

namespace ts::sdf {
namespace {

// The cache file, its format line and the two paths' keys: "compute" first (it wins ties).
const gpu::CalibrationKind& scan_kind() {
  static const gpu::CalibrationKind kind{"scan", kScanCacheVariable, "compute", "geometry"};
  return kind;
}

}  // namespace

std::string scan_build_id() { return gpu::build_id(); }

std::optional<std::filesystem::path> scan_cache_path() { return gpu::calibration_cache_path(scan_kind()); }

ScanTiming calibrate_scan(gpu::Context& context) {
  const TriangleMesh mesh = make_icosphere(0.5, 4);
  SdfSettings settings;
  settings.resolution = 48;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  const Pseudonormals normals = compute_pseudonormals(mesh);
  auto seconds = [&](ScanMethod method) {
    ScanConvertOptions options;
    options.method = method;
    options.build_grid = false;  // the scan conversion alone: both paths share what comes after
    return scan_convert(context, mesh, normals, spec, options).stats.seconds;
  };
  // Each path twice, alternating: the first run of each also compiles its programs (kept by the
  // context afterwards), and alternating spreads a load that changes meanwhile over both.
  ScanTiming timing{1e300, 1e300};
  for (int round = 0; round < 2; ++round) {
    timing.compute_seconds = std::min(timing.compute_seconds, seconds(ScanMethod::Compute));
    timing.geometry_seconds = std::min(timing.geometry_seconds, seconds(ScanMethod::Geometry));
  }
  return timing;
}

ScanChoice choose_scan(gpu::Context& context, std::string_view requested,
                       const std::optional<std::filesystem::path>& cache,
                       const std::function<ScanTiming()>& calibrate) {
  if (requested != "auto") {
    const std::optional<ScanMethod> method = parse_scan_method(requested);
    if (!method) throw InputError(fmt::format("--scan {}: expected compute, geometry or auto", requested));
    return {*method, "--scan"};
  }
  const gpu::PathChoice choice = gpu::choose_calibrated_path(context, scan_kind(), cache, [&calibrate] {
    const ScanTiming timing = calibrate();
    return gpu::PathTiming{timing.compute_seconds, timing.geometry_seconds};
  });
  return {choice.first ? ScanMethod::Compute : ScanMethod::Geometry, choice.reason};
}

ScanChoice choose_scan(gpu::Context& context, std::string_view requested) {
  return choose_scan(context, requested, scan_cache_path(), [&context] { return calibrate_scan(context); });
}

}  // namespace ts::sdf
