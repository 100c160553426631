#include "fuzz/run_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "body/particles_ply.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "scene/scene_limits.h"
#include "scene/scene_world.h"

namespace ts::fuzz {
namespace fs = std::filesystem;

void fail_check(std::string_view what) {
  std::fprintf(stderr, "fuzz check failed: %.*s\n", static_cast<int>(what.size()), what.data());
  std::abort();
}

namespace {

std::size_t g_refused = 0, g_stopped = 0, g_passed = 0;

void require_finite(const Eigen::Vector3d& v, const char* what, std::size_t index) {
  if (!v.allFinite()) fail_check(fmt::format("{} {} is not finite on an exit-0 run", what, index));
}

// Positions, velocities and orientations finite; every particle within the grid's reach of the
// origin in cells of the largest particle diameter (the bound docs/reliability.md states).
void require_sane_world(const sim::World& world) {
  const sim::Bodies& b = world.bodies;
  for (std::size_t i = 0; i < b.size(); ++i) {
    require_finite(b.position[i], "body position", i);
    require_finite(b.linear_velocity[i], "body velocity", i);
    require_finite(b.angular_velocity[i], "body angular velocity", i);
    if (!b.orientation[i].coeffs().allFinite()) fail_check(fmt::format("body {} orientation not finite", i));
  }
  double diameter = 0;
  for (double r : world.particles.radius) diameter = std::max(diameter, 2 * r);
  const std::vector<Eigen::Vector3d> positions = sim::particle_positions(world);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    require_finite(positions[i], "particle", i);
    const double cells = positions[i].cwiseAbs().maxCoeff() / diameter;
    if (cells > sim::kMaxCellCoordinate) {
      fail_check(fmt::format("particle {} is {:.3g} cells from the origin, past the documented {:.0g}", i, cells,
                             sim::kMaxCellCoordinate));
    }
  }
  if (!std::isfinite(world.time)) fail_check("the world's time is not finite");
}

void require_sane_stats(const sim::StepStats& s) {
  const double values[] = {s.energy.translational, s.energy.rotational, s.energy.potential, s.elastic_energy,
                           s.max_overlap_ratio};
  for (double v : values)
    if (!std::isfinite(v)) fail_check("a step's energies or overlap are not finite on an exit-0 run");
}

// Every comma-separated field of metrics.csv after the header row parses as a finite number.
void require_finite_csv(const fs::path& file) {
  const std::string text = read_file(file);
  std::size_t line_start = text.find('\n');
  if (line_start == std::string::npos) return;
  std::size_t row = 1;
  for (std::size_t at = line_start + 1; at < text.size(); ++row) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string line = text.substr(at, end - at);
    std::size_t field_start = 0;
    while (field_start <= line.size()) {
      const std::size_t comma = std::min(line.find(',', field_start), line.size());
      const std::string field = line.substr(field_start, comma - field_start);
      char* parsed_end = nullptr;
      const double v = std::strtod(field.c_str(), &parsed_end);
      if (field.empty() || parsed_end != field.c_str() + field.size() || !std::isfinite(v))
        fail_check(fmt::format("{} row {}: field '{}' is not a finite number", file.string(), row, field));
      field_start = comma + 1;
    }
    at = end + 1;
  }
}

}  // namespace

scene::RunHooks checking_hooks() {
  scene::RunHooks hooks;
  hooks.on_output = [](const sim::World& world, const sim::StepStats& stats, std::int64_t) {
    require_sane_world(world);
    require_sane_stats(stats);
  };
  return hooks;
}

void require_finite_files(const fs::path& output_dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(output_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name == "metrics.csv") require_finite_csv(entry.path());
    if (name.starts_with("particles_") && name.ends_with(".ply")) {
      for (const Eigen::Vector3f& p : body::read_particles_ply(entry.path()).positions)
        if (!p.allFinite()) fail_check(fmt::format("{} holds a non-finite position", name));
    }
  }
}

void run_and_check(const scene::Scene& scene, const fs::path& output_dir, scene::RunControl control,
                   std::int64_t max_steps) {
  try {
    if (!control.resume) {
      const sim::World world = scene::make_world(scene);
      const double dt = scene::resolve_time_step(scene, world, nullptr);
      control.duration = std::min(scene.simulation.duration, static_cast<double>(max_steps) * dt);
    }
    (void)scene::run_scene(scene, output_dir, checking_hooks(), {}, control);
  } catch (const Error& e) {
    if (e.code() == ExitCode::BadInput || e.code() == ExitCode::Unstable) {
      ++(e.code() == ExitCode::BadInput ? g_refused : g_stopped);
      return;
    }
    fail_check(fmt::format("exit {}: {}", static_cast<int>(e.code()), e.what()));
  } catch (const std::exception& e) {
    fail_check(fmt::format("an internal error (exit 5): {}", e.what()));
  }
  require_finite_files(output_dir);
  ++g_passed;
}

const char* run_summary() {
  static std::string line;
  line = fmt::format("{} runs: {} refused (exit 1), {} stopped (exit 4), {} ran to exit 0 and passed the checks",
                     g_refused + g_stopped + g_passed, g_refused, g_stopped, g_passed);
  return line.c_str();
}

}  // namespace ts::fuzz

extern "C" const char* TetrasandFuzzSummary() { return ts::fuzz::run_summary(); }
