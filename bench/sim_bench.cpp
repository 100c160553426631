// Cundall number (grain time steps per second) of the GPU pipeline and of the CPU reference on the
// same scene, in one run, as ratios. Usage:
//   tetrasand_bench_sim [--grains 1000,8000] [--seconds 3] [--precision float|double] [--markdown]
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_scenes.h"
#include "gpu/context.h"
#include "sim/cpu_reference.h"
#include "sim/gpu_stepper.h"
#include "sim/time_step.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::vector<std::uint32_t> grains{1000, 8000};
  double seconds = 3.0;  // wall time per measurement
  ts::sim::Precision precision = ts::sim::Precision::Float;
  bool markdown = false;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error("missing value after " + arg);
      return argv[++i];
    };
    if (arg == "--grains") {
      o.grains.clear();
      std::stringstream list(next());
      for (std::string item; std::getline(list, item, ',');) o.grains.push_back(static_cast<std::uint32_t>(std::stoul(item)));
    } else if (arg == "--seconds") {
      o.seconds = std::stod(next());
    } else if (arg == "--precision") {
      o.precision = next() == "double" ? ts::sim::Precision::Double : ts::sim::Precision::Float;
    } else if (arg == "--markdown") {
      o.markdown = true;
    } else {
      throw std::runtime_error("unknown option " + arg);
    }
  }
  return o;
}

// Steps until `seconds` of wall time have passed (at least `min_steps`); returns steps per second.
template <typename StepFn, typename SyncFn>
double steps_per_second(StepFn step, SyncFn sync, double seconds, int batch) {
  step(batch);  // warm-up: shader compilation, first allocations
  sync();
  int steps = 0;
  const auto start = Clock::now();
  double elapsed = 0.0;
  while (elapsed < seconds) {
    step(batch);
    sync();
    steps += batch;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  }
  return steps / elapsed;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    ts::gpu::Context context;
    ts::sim::StepSettings settings;
    settings.dt = 2e-6;  // s: below t_c/20 for 1 mm grains at 1 m/s with E = 10 MPa
    const std::string header = fmt::format("| grains | GPU grain-steps/s | CPU grain-steps/s | GPU / CPU |");
    if (options.markdown) fmt::print("{}\n|---|---|---|---|\n", header);
    fmt::print(stderr, "renderer: {}\n", context.summary());
    for (std::uint32_t grains : options.grains) {
      const ts::sim::World world = ts::bench::settling_box(grains, 1);
      ts::sim::GpuStepper gpu(context, world, settings, options.precision);
      const double gpu_rate = steps_per_second([&](int n) { gpu.step(n); }, [&] { glFinish(); }, options.seconds, 10);
      ts::sim::World cpu_world = world;
      ts::sim::CpuStepper cpu(cpu_world, settings);
      const double cpu_rate = steps_per_second(
          [&](int n) {
            for (int s = 0; s < n; ++s) cpu.step(cpu_world);
          },
          [] {}, options.seconds, 2);
      const double g = gpu_rate * grains, c = cpu_rate * grains;
      if (options.markdown) {
        fmt::print("| {} | {:.3g} | {:.3g} | {:.2f} |\n", grains, g, c, g / c);
      } else {
        fmt::print("grains {:>8}: GPU {:.3g} grain-steps/s, CPU reference {:.3g} grain-steps/s, ratio {:.2f}\n", grains,
                   g, c, g / c);
      }
    }
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
}
