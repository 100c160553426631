// `tetrasand sim SCENE.toml`: run a sand scene on the GPU pipeline or the CPU reference (--backend).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <tuple>
#include <utility>

#include "app/commands.h"
#include "app/numeric_options.h"
#include "app/progress.h"
#include "core/log.h"
#include "gpu/backend.h"
#include "gpu/context.h"
#include "preview/sim_frames.h"
#include "sim/gpu_stepper.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"

namespace ts::app {
namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string scene;
  std::string output = "sim-out";
  double duration = 0;  // s; 0 = the scene's
  std::string backend = "auto";  // auto, gpu or cpu
  bool cpu = false;              // --cpu: the alias of --backend cpu
  std::string precision;         // float or double; empty: not given (float on the GPU)
  bool timings = false;
  bool json = false;   // the run's summary as JSON on standard output (the human lines then go to the log)
  std::string resume;  // DIR: go on from its latest checkpoint, writing there
};

void add_options(CLI::App* cmd, Options& o) {
  cmd->add_option("SCENE", o.scene, "Scene file (TOML; see assets/scenes/README.md)")->required()->check(CLI::ExistingFile);
  CLI::Option* output = cmd->add_option("-o,--output", o.output,
                                        "Output directory (metrics.csv, particle dumps, frames, checkpoints)")
                            ->capture_default_str();
  cmd->add_option("--duration", o.duration, "Simulated time [s], overriding the scene's")->check(positive());
  CLI::Option* backend =
      cmd->add_option(
             "--backend", o.backend,
             "auto: the GPU pipeline on a hardware GPU, the double-precision CPU reference when the GL "
             "device is a software renderer (Mesa llvmpipe, where the CPU reference is 3-30x faster); "
             "gpu or cpu: that one")
          ->check(CLI::IsMember({"auto", "gpu", "cpu"}))
          ->capture_default_str();
  cmd->add_flag("--cpu", o.cpu, "Alias of --backend cpu (the double-precision CPU reference)")
      ->excludes(backend);
  cmd->add_option(
         "--precision", o.precision,
         "GPU pipeline arithmetic: float (default) or double (GLSL fp64); the CPU reference is always "
         "double, so --backend cpu refuses it")
      ->check(CLI::IsMember({"float", "double"}));
  cmd->add_flag("--timings", o.timings, "Print per-kernel GPU times and host-GPU round trips at the end");
  cmd->add_flag("--json", o.json,
                "Print the run's summary (engine, steps, rate, bodies, clamps, outputs, last step's energies; "
                "--timings' report as a string) as JSON on standard output");
  cmd->add_option(
         "--resume", o.resume,
         "Go on from the latest checkpoint in DIR (written with [output] checkpoint_every or "
         "checkpoint_seconds) and write the outputs there; the result is bit for bit the uninterrupted run's")
      ->type_name("DIR")
      ->excludes(output);
}

// The progress line of one output: time, step rate, contacts and the time left (app/progress.h shows
// it live on a terminal, a tenth of the run a line in a pipe). `first_step` and `first_time` (s):
// where this process started (a resumed run starts late).
void report_progress(Progress& progress, double duration, const sim::World& world, const sim::StepStats& stats,
                     std::int64_t step, Clock::time_point start, std::int64_t first_step, double first_time) {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  const double rate = elapsed > 0 ? static_cast<double>(step - first_step) / elapsed : 0.0;
  const double done = world.time - first_time;  // s simulated by this process
  const double remaining = done > 0 ? (duration - world.time) / done * elapsed : 0.0;
  const double fraction = duration > first_time ? done / (duration - first_time) : -1.0;
  progress.update(fmt::format("t = {:.4f} / {:.4f} s  step {}  {:.0f} steps/s  contacts {}  ETA {:.0f} s",
                              world.time, duration, step, rate, stats.contacts, remaining),
                  fraction);
}

// "360 grains; props: 1 dynamic; static bodies: 2 rough walls; smooth walls: 5 planes" (kinds with
// none left out, so a grain-only scene reads "360 grains").
std::string describe_bodies(const scene::BodyCounts& c) {
  const auto plural = [](std::size_t n, std::string_view what) {
    return fmt::format("{} {}{}", n, what, n == 1 ? "" : "s");
  };
  std::vector<std::string> parts{plural(c.grains, "grain")};
  std::vector<std::string> props;
  if (c.dynamic_props > 0) props.push_back(fmt::format("{} dynamic", c.dynamic_props));
  if (c.kinematic_props > 0) props.push_back(fmt::format("{} kinematic", c.kinematic_props));
  if (c.static_props > 0) props.push_back(fmt::format("{} static", c.static_props));
  if (!props.empty()) parts.push_back(fmt::format("props: {}", fmt::join(props, ", ")));
  if (c.rough_walls > 0) parts.push_back(fmt::format("static bodies: {} (rough walls)", c.rough_walls));
  std::vector<std::string> smooth;
  if (c.smooth_planes > 0) smooth.push_back(plural(c.smooth_planes, "plane"));
  if (c.smooth_cylinders > 0) smooth.push_back(plural(c.smooth_cylinders, "cylinder"));
  if (!smooth.empty()) parts.push_back(fmt::format("smooth walls: {}", fmt::join(smooth, ", ")));
  return fmt::format("{}", fmt::join(parts, "; "));
}

// --backend, or cpu for its alias --cpu. --precision with the CPU reference is a usage error: it
// would be ignored (the reference computes in double), and a user who gives it means the GPU.
std::string requested_backend(const Options& o) {
  const std::string requested = o.cpu ? "cpu" : o.backend;
  if (requested == "cpu" && !o.precision.empty()) {
    throw Error(ExitCode::Usage,
                fmt::format("--precision {}: the CPU reference (--backend cpu) computes in double "
                            "only; --precision sets the GPU pipeline's arithmetic",
                            o.precision));
  }
  return requested;
}

// The GL context a run needs (the GPU pipeline's, or only the frames' renderer's; null when neither)
// and the engine that runs the steps: the GPU pipeline (sim/gpu_stepper.h) or the CPU reference
// (sim/cpu_stepper.h), by the rule of gpu/backend.h, named in its one line. A device that cannot
// make a context at all stays an error (exit 3) under auto, as under --backend gpu: a broken driver on
// a GPU machine should say so, not turn into a much slower run.
gpu::Backend choose_backend(const Options& o, const GlobalOptions& global, const scene::Scene& scene,
                            std::unique_ptr<gpu::Context>& context) {
  const bool frames = scene.output.frames;
  const gpu::Backend requested = gpu::parse_backend(requested_backend(o)).value();  // IsMember checked it
  if (requested != gpu::Backend::Cpu || frames) context = std::make_unique<gpu::Context>(context_options(global));
  const gpu::Backend chosen = gpu::resolve_backend(requested, context.get());
  const bool cpu = chosen == gpu::Backend::Cpu;
  const bool precision_ignored = cpu && !o.precision.empty();  // auto only: --cpu with it is refused
  const std::string precision_note =
      precision_ignored ? "--precision applies to the GPU pipeline only, the CPU reference computes in double" : "";
  const std::string line = gpu::backend_line(requested, chosen, gpu::describe(context.get()), true,
                                             cpu ? "the CPU reference" : "the GPU pipeline", precision_note);
  if (o.json) {
    log::info("{}", line);  // standard output stays the JSON
  } else {
    fmt::print("{}\n", line);
    std::fflush(stdout);
  }
  if (cpu && !frames) context.reset();
  return chosen;
}

const std::string& output_dir(const Options& o) { return o.resume.empty() ? o.output : o.resume; }

// ", set by bonds (bound: t_c/20 = ..., bonds = ...)" for an automatic step; " (by hand; ...)" otherwise.
std::string describe_bound(const scene::Scene& scene, const scene::RunResult& result) {
  const sim::TimeStepBound& b = result.bound;
  const std::string bonds = std::isfinite(b.bonds) ? fmt::format(", bonds {:.3g} s", b.bonds) : "";
  const std::string terms = fmt::format("t_c/20 = {:.3g} s at {:.3g} m/s, 0.2 t_R = {:.3g} s, m_t/gamma_s = {:.3g} s{}",
                                        b.contact_duration / 20, b.max_impact_speed, 0.2 * b.rayleigh, b.tangential,
                                        bonds);
  if (scene.simulation.dt > 0) return fmt::format(" (by hand; the bound is {:.3g} s: {})", b.recommended, terms);
  return fmt::format(", set by {} ({})", sim::limiting_bound(b), terms);
}

void print_summary(const Options& o, const scene::Scene& scene, const scene::RunResult& result, double seconds,
                   gpu::Backend backend, const gpu::Context* context) {
  // Steps this process ran (a resumed run started at resumed_from).
  const auto stepped = static_cast<double>(result.steps - std::max<std::int64_t>(result.resumed_from, 0));
  fmt::print("{}: {} steps of {:.3g} s, {} grains, {:.1f} s wall ({:.3g} grain-steps/s, {})\n", o.scene,
             result.steps, result.dt, result.grains, seconds,
             seconds > 0 ? stepped * static_cast<double>(result.grains) / seconds : 0.0,
             backend == gpu::Backend::Cpu ? "CPU reference" : context->summary());
  fmt::print("time step: {:.3g} s{}\n", result.dt, describe_bound(scene, result));
  fmt::print("bodies: {}\n", describe_bodies(result.bodies));
  if (scene.has_bonds()) {
    fmt::print("bonds: {} at the start, {} intact and {} broken at the end; {} fragment{} (the largest {:.4g} kg)\n",
               result.bonds_at_start, result.bonds.intact, result.bonds.broken, result.bonds.fragments,
               result.bonds.fragments == 1 ? "" : "s", result.bonds.largest_fragment_mass);
  }
  fmt::print("clamps: {} velocity, {} angular velocity, {} overlap (each clamp means a less accurate result)\n",
             result.last.velocity_clamps, result.last.angular_velocity_clamps, result.last.overlap_clamps);
  if (scene.simulation.step.tangential == sim::TangentialModel::Spring) {
    fmt::print("spring slots: {} overflows over the run (a contact past {} per particle has no static friction)\n",
               result.spring_overflows, sim::ContactSprings::kSlots);
  }
  if (result.resumed_from >= 0) fmt::print("resumed from the checkpoint at step {}\n", result.resumed_from);
  if (result.checkpoints > 0)
    fmt::print("checkpoints: {} written in {}\n", result.checkpoints, output_dir(o));
  std::vector<std::string> files;
  for (const scene::OutputRecord& f : result.files)
    files.push_back(fmt::format("{} ({} {})", (std::filesystem::path(output_dir(o)) / f.pattern).string(),
                                f.count, f.unit));
  fmt::print("outputs: {}\n", files.empty() ? std::string("none ([output] writes nothing)")
                                            : fmt::format("{}", fmt::join(files, ", ")));
}

// The summary of print_summary, and the last step's state, as one JSON object (--json).
void print_json(const Options& o, const scene::RunResult& result, double seconds, const std::string& engine,
                const std::string& timing_report, bool scene_dt_by_hand) {
  const auto stepped = static_cast<double>(result.steps - std::max<std::int64_t>(result.resumed_from, 0));
  const scene::BodyCounts& b = result.bodies;
  nlohmann::ordered_json outputs = nlohmann::ordered_json::array();
  for (const scene::OutputRecord& f : result.files) {
    outputs.push_back({{"pattern", f.pattern},
                       {"path", (std::filesystem::path(output_dir(o)) / f.pattern).string()},
                       {"count", f.count},
                       {"unit", f.unit}});
  }
  const sim::StepStats& last = result.last;
  const nlohmann::ordered_json out = {
      {"scene", o.scene},
      {"output", output_dir(o)},
      {"engine", engine},
      {"steps", result.steps},
      {"resumed_from", result.resumed_from >= 0 ? nlohmann::ordered_json(result.resumed_from) : nullptr},
      {"dt_s", result.dt},
      {"dt_set_by", scene_dt_by_hand ? std::string("hand") : sim::limiting_bound(result.bound)},
      {"time_step_warning", result.time_step_warning.empty() ? nlohmann::ordered_json(nullptr)
                                                             : nlohmann::ordered_json(result.time_step_warning)},
      {"grains", result.grains},
      {"wall_seconds", seconds},
      {"grain_steps_per_second", seconds > 0 ? stepped * static_cast<double>(result.grains) / seconds : 0.0},
      {"bodies",
       {{"grains", b.grains}, {"dynamic_props", b.dynamic_props}, {"kinematic_props", b.kinematic_props},
        {"static_props", b.static_props}, {"rough_walls", b.rough_walls}, {"smooth_planes", b.smooth_planes},
        {"smooth_cylinders", b.smooth_cylinders}}},
      {"clamps", {{"velocity", last.velocity_clamps}, {"angular_velocity", last.angular_velocity_clamps},
                  {"overlap", last.overlap_clamps}}},
      {"spring_overflows", result.spring_overflows},
      {"last_step",
       {{"kinetic_translational_J", last.energy.translational}, {"kinetic_rotational_J", last.energy.rotational},
        {"potential_J", last.energy.potential}, {"contacts", last.contacts}, {"wall_contacts", last.wall_contacts},
        {"max_overlap_ratio", last.max_overlap_ratio}}},
      {"bonds",
       {{"at_start", result.bonds_at_start}, {"intact", result.bonds.intact}, {"broken", result.bonds.broken},
        {"fragments", result.bonds.fragments}, {"largest_fragment_kg", result.bonds.largest_fragment_mass}}},
      {"checkpoints", result.checkpoints},
      {"outputs", outputs},
      {"timings", timing_report.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(timing_report)},
  };
  fmt::print("{}\n", out.dump(2));
}

int run_sim(const Options& o, const GlobalOptions& global) {
  requested_backend(o);  // a usage error before any work
  const scene::Scene scene = scene::load_scene(o.scene);
  std::unique_ptr<gpu::Context> context;
  const gpu::Backend backend = choose_backend(o, global, scene, context);
  scene::StepperFactory make_stepper;  // empty: the CPU reference
  if (backend == gpu::Backend::Gpu) {
    const auto precision = o.precision == "double" ? sim::Precision::Double : sim::Precision::Float;
    make_stepper = [&, precision](const sim::StepSettings& settings) -> std::unique_ptr<sim::Stepper> {
      return std::make_unique<sim::GpuStepper>(*context, settings, precision, o.timings);
    };
  }
  Progress progress;
  const auto start = Clock::now();
  scene::RunHooks hooks;
  std::unique_ptr<preview::SimFrameWriter> frames;  // [output] frames = true: PNGs through the preview renderer
  if (scene.output.frames) {
    frames = std::make_unique<preview::SimFrameWriter>(*context, scene);
    hooks.write_frame = [&frames](const sim::World& world, std::int64_t frame, const std::filesystem::path& dir) {
      frames->write(world, frame, dir);
    };
  }
  std::int64_t first_step = -1;
  double first_time = 0;
  const double duration =
      o.duration > 0 ? o.duration : scene.simulation.duration;  // s (a resumed run: its own)
  hooks.on_output = [&](const sim::World& world, const sim::StepStats& stats, std::int64_t step) {
    if (first_step < 0) std::tie(first_step, first_time) = std::pair(step, world.time);
    report_progress(progress, duration, world, stats, step, start, first_step, first_time);
  };
  std::string timing_report;
  std::string engine = backend == gpu::Backend::Cpu ? "cpu reference" : "gpu " + (o.precision.empty() ? std::string("float") : o.precision);
  hooks.on_finish = [&](sim::Stepper& stepper) {
    engine = stepper.engine();
    if (o.timings) timing_report = stepper.timing_report();
  };
  scene::RunControl control;
  control.resume = !o.resume.empty();
  control.duration = o.duration;
  const scene::RunResult result = scene::run_scene(scene, output_dir(o), hooks, make_stepper, control);
  progress.end();
  if (!result.time_step_warning.empty()) log::warn("{}", result.time_step_warning);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (o.json) {
    print_json(o, result, seconds, engine, timing_report, scene.simulation.dt > 0);
    return 0;
  }
  print_summary(o, scene, result, seconds, backend, context.get());
  if (!timing_report.empty()) fmt::print("{}", timing_report);
  return 0;
}

}  // namespace

Runner add_sim_command(CLI::App& app, const GlobalOptions& global) {
  return add_command<Options>(app, global, "sim",
                              "Run a tetrahedral-grain DEM scene (TOML) on the GPU or the CPU reference",
                              run_sim, add_options);
}

}  // namespace ts::app
