#include "sdf/scan_calibration.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <nlohmann/json.hpp>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/mesh.h"
#include "core/primitives.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"

namespace ts::sdf {
namespace {

// The first line of a cache file's JSON: a file without it (or of another version) is not ours.
constexpr const char* kCacheFormat = "tetrasand scan calibration 1";
// Larger cache files are not read (a few entries take a few hundred bytes).
constexpr std::uint64_t kMaxCacheBytes = 1 << 20;

std::optional<std::filesystem::path> environment_path(const char* variable) {
  const char* value = std::getenv(variable);
  if (value == nullptr || *value == '\0') return std::nullopt;
  return std::filesystem::path(value);
}

// The cache's entries, or an empty array when there is no file yet. A file that is unreadable, not
// JSON, or not a calibration cache is ignored with a warning and will be replaced.
nlohmann::json read_entries(const std::filesystem::path& cache) {
  std::error_code missing;
  if (!std::filesystem::exists(cache, missing)) return nlohmann::json::array();
  try {
    const nlohmann::json file =
        nlohmann::json::parse(read_file(cache, kMaxCacheBytes, "a scan calibration cache"));
    if (file.is_object() && file.value("format", "") == kCacheFormat && file.contains("entries") &&
        file["entries"].is_array())
      return file["entries"];
    log::warn("{}: not a tetrasand scan calibration cache ({}); ignoring it and calibrating again",
              cache.string(), kCacheFormat);
  } catch (const std::exception& e) {
    log::warn("{}: unreadable scan calibration cache ({}); ignoring it and calibrating again", cache.string(),
              e.what());
  }
  return nlohmann::json::array();
}

// Whether cache entry `e` was timed on this renderer and driver (by any build).
bool same_device(const nlohmann::json& e, const gpu::Context& context) {
  return e.is_object() && e.value("renderer", "") == context.renderer() &&
         e.value("version", "") == context.version();
}

// Whether cache entry `e` was timed by this build on this renderer and driver.
bool same_setup(const nlohmann::json& e, const gpu::Context& context) {
  return same_device(e, context) && e.value("build", "") == scan_build_id();
}

// The entry of `entries` for this build, renderer and driver with both timings positive, if any.
std::optional<ScanTiming> find_entry(const nlohmann::json& entries, const gpu::Context& context) {
  for (const nlohmann::json& e : entries) {
    if (!same_setup(e, context)) continue;
    const double compute = e.value("compute_seconds", 0.0), geometry = e.value("geometry_seconds", 0.0);
    if (compute > 0.0 && geometry > 0.0) return ScanTiming{compute, geometry};
  }
  return std::nullopt;
}

// Stores `timing` for this build, renderer and driver, keeping the other renderers' entries (another
// build's entry for this renderer and driver is stale: replaced). A failed write only costs the next
// run a calibration.
void store_entry(const std::filesystem::path& cache, nlohmann::json entries, const gpu::Context& context,
                 const ScanTiming& timing) {
  nlohmann::json kept = nlohmann::json::array();
  for (const nlohmann::json& e : entries)
    if (e.is_object() && !same_device(e, context)) kept.push_back(e);
  kept.push_back({{"renderer", context.renderer()},
                  {"version", context.version()},
                  {"build", scan_build_id()},
                  {"compute_seconds", timing.compute_seconds},
                  {"geometry_seconds", timing.geometry_seconds}});
  const nlohmann::json file = {{"format", kCacheFormat}, {"entries", kept}};
  try {
    std::filesystem::create_directories(cache.parent_path());
    write_file_atomically(cache, file.dump(2) + "\n");
  } catch (const std::exception& e) {
    log::warn("{}: scan calibration not cached ({})", cache.string(), e.what());
  }
}

// Compute unless geometry was faster; the reason names the speed ratio (geometry's time over
// compute's: above 1 compute is faster).
ScanChoice choice_of(const ScanTiming& timing, bool cached) {
  const double ratio = timing.geometry_seconds / timing.compute_seconds;
  return {ratio >= 1.0 ? ScanMethod::Compute : ScanMethod::Geometry,
          fmt::format("calibrated {:.2g}x geometry's speed{}", ratio, cached ? ", cached" : "")};
}

}  // namespace

std::string scan_build_id() {
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return "unknown";
  const std::uintmax_t bytes = std::filesystem::file_size(exe, error);
  if (error) return "unknown";
  const auto written = std::filesystem::last_write_time(exe, error);
  if (error) return "unknown";
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(
      std::chrono::file_clock::to_sys(written).time_since_epoch());
  return fmt::format("{} bytes, written at {} s since 1970", bytes, seconds.count());
}

std::optional<std::filesystem::path> scan_cache_path() {
  if (auto path = environment_path(kScanCacheVariable)) return path;
  if (auto xdg = environment_path("XDG_CACHE_HOME")) return *xdg / "tetrasand" / "scan_calibration.json";
  if (auto home = environment_path("HOME")) return *home / ".cache" / "tetrasand" / "scan_calibration.json";
  return std::nullopt;
}

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
  const nlohmann::json entries = cache ? read_entries(*cache) : nlohmann::json::array();
  if (const std::optional<ScanTiming> known = find_entry(entries, context)) return choice_of(*known, true);
  log::info("--scan auto: timing both scan conversions once on {} / {}", context.renderer(),
            context.version());
  const ScanTiming timing = calibrate();
  if (!(timing.compute_seconds > 0.0 && timing.geometry_seconds > 0.0)) {
    return {ScanMethod::Compute, "calibration timed nothing"};
  }
  if (cache) store_entry(*cache, entries, context, timing);
  return choice_of(timing, false);
}

ScanChoice choose_scan(gpu::Context& context, std::string_view requested) {
  return choose_scan(context, requested, scan_cache_path(), [&context] { return calibrate_scan(context); });
}

}  // namespace ts::sdf
