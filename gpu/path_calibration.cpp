#include "gpu/path_calibration.h"

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <exception>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/log.h"

namespace ts::gpu {
namespace {

// Larger cache files are not read (a few entries take a few hundred bytes).
constexpr std::uint64_t kMaxCacheBytes = 1 << 20;

// The first line of a cache file's JSON: a file without it (or of another version) is not ours.
std::string format_line(const CalibrationKind& kind) {
  return fmt::format("tetrasand {} calibration 1", kind.stage);
}

std::optional<std::filesystem::path> environment_path(const char* variable) {
  const char* value = std::getenv(variable);
  if (value == nullptr || *value == '\0') return std::nullopt;
  return std::filesystem::path(value);
}

// The cache's entries, or an empty array when there is no file yet. A file that is unreadable, not
// JSON, or not this stage's calibration cache is ignored with a warning and will be replaced.
nlohmann::json read_entries(const std::filesystem::path& cache, const CalibrationKind& kind) {
  std::error_code missing;
  if (!std::filesystem::exists(cache, missing)) return nlohmann::json::array();
  const std::string what = fmt::format("{} calibration cache", kind.stage);
  try {
    const nlohmann::json file = nlohmann::json::parse(read_file(cache, kMaxCacheBytes, "a " + what));
    if (file.is_object() && file.value("format", "") == format_line(kind) && file.contains("entries") &&
        file["entries"].is_array())
      return file["entries"];
    log::warn("{}: not a tetrasand {} ({}); ignoring it and calibrating again", cache.string(), what,
              format_line(kind));
  } catch (const std::exception& e) {
    log::warn("{}: unreadable {} ({}); ignoring it and calibrating again", cache.string(), what, e.what());
  }
  return nlohmann::json::array();
}

// Whether cache entry `e` was timed on this renderer and driver (by any build).
bool same_device(const nlohmann::json& e, const Context& context) {
  return e.is_object() && e.value("renderer", "") == context.renderer() &&
         e.value("version", "") == context.version();
}

// The entry of `entries` for this build, renderer and driver with both timings positive, if any.
std::optional<PathTiming> find_entry(const nlohmann::json& entries, const Context& context,
                                     const CalibrationKind& kind) {
  for (const nlohmann::json& e : entries) {
    if (!same_device(e, context) || e.value("build", "") != build_id()) continue;
    const double first = e.value(kind.first + "_seconds", 0.0), second = e.value(kind.second + "_seconds", 0.0);
    if (first > 0.0 && second > 0.0) return PathTiming{first, second};
  }
  return std::nullopt;
}

// Stores `timing` for this build, renderer and driver after the entries of other renderers and of up to
// kBuildsPerDevice - 1 other builds on this one (the newest: entries are kept oldest first). Other
// builds are kept because several executables share a cache (the tool and a test program, two installed
// versions), and dropped beyond that so a rebuilt tetrasand does not grow the file. A failed write only
// costs the next run a calibration.
constexpr std::size_t kBuildsPerDevice = 4;

void store_entry(const std::filesystem::path& cache, const nlohmann::json& entries, const Context& context,
                 const CalibrationKind& kind, const PathTiming& timing) {
  const std::string build = build_id();
  std::size_t older_builds = 0;
  for (const nlohmann::json& e : entries)
    older_builds += same_device(e, context) && e.value("build", "") != build ? 1 : 0;
  nlohmann::json kept = nlohmann::json::array();
  std::size_t skip = older_builds > kBuildsPerDevice - 1 ? older_builds - (kBuildsPerDevice - 1) : 0;
  for (const nlohmann::json& e : entries) {
    if (!e.is_object()) continue;
    if (same_device(e, context)) {
      if (e.value("build", "") == build) continue;  // this build's entry, timed again (an invalid one)
      if (skip > 0) {
        --skip;
        continue;
      }
    }
    kept.push_back(e);
  }
  kept.push_back({{"renderer", context.renderer()},
                  {"version", context.version()},
                  {"build", build},
                  {kind.first + "_seconds", timing.first_seconds},
                  {kind.second + "_seconds", timing.second_seconds}});
  const nlohmann::json file = {{"format", format_line(kind)}, {"entries", kept}};
  try {
    std::filesystem::create_directories(cache.parent_path());
    write_file_atomically(cache, file.dump(2) + "\n");
  } catch (const std::exception& e) {
    log::warn("{}: {} calibration not cached ({})", cache.string(), kind.stage, e.what());
  }
}

// `first` unless `second` was faster; the reason names the speed ratio (second's time over first's:
// above 1 the first path is faster).
PathChoice choice_of(const PathTiming& timing, const CalibrationKind& kind, bool cached) {
  const double ratio = timing.second_seconds / timing.first_seconds;
  return {ratio >= 1.0, fmt::format("calibrated {:.2g}x {}'s speed{}", ratio, kind.second, cached ? ", cached" : "")};
}

}  // namespace

std::string build_id() {
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

std::optional<std::filesystem::path> calibration_cache_path(const CalibrationKind& kind) {
  const std::string file = kind.stage + "_calibration.json";
  if (auto path = environment_path(kind.cache_variable.c_str())) return path;
  if (auto xdg = environment_path("XDG_CACHE_HOME")) return *xdg / "tetrasand" / file;
  if (auto home = environment_path("HOME")) return *home / ".cache" / "tetrasand" / file;
  return std::nullopt;
}

PathChoice choose_calibrated_path(const Context& context, const CalibrationKind& kind,
                                  const std::optional<std::filesystem::path>& cache,
                                  const std::function<PathTiming()>& calibrate) {
  const nlohmann::json entries = cache ? read_entries(*cache, kind) : nlohmann::json::array();
  if (const std::optional<PathTiming> known = find_entry(entries, context, kind))
    return choice_of(*known, kind, true);
  log::info("{} auto: timing the {} and {} paths once on {} / {}", kind.stage, kind.first, kind.second,
            context.renderer(), context.version());
  const PathTiming timing = calibrate();
  if (!(timing.first_seconds > 0.0 && timing.second_seconds > 0.0)) return {true, "calibration timed nothing"};
  if (cache) store_entry(*cache, entries, context, kind, timing);
  return choice_of(timing, kind, false);
}

}  // namespace ts::gpu
