// The measured trade of Young's modulus, time step and precision against accuracy, on the CPU
// reference (double) and the GPU pipeline (float and double), in one run. Usage:
//   tetrasand_bench_sim_accuracy OUT_DIR [energy|pile|all] [--quick] [--backends cpu,gpu-float,...]
// energy: reference/elastic_box.toml (no dissipation) at E = 1e6, 1e7, 1e8 Pa and dt = 0.5, 1, 2 x the
//         automatic bound: largest overlap / r over every step and the largest drift of mechanical
//         energy (kinetic + potential + Hertz spring) over the initial potential energy above the floor
//         -> energy.csv
// pile:   reference/heap.toml with 150 grains on a 6 cm floor (forward Euler, the scene's integrator)
//         at E = 1e6 Pa and dt = 1, 2 x the bound: the resting heap's grain centres (heap_*.csv;
//         bench/plot_sim_accuracy.py fits its angle of repose) and the largest overlap / r at the
//         outputs -> pile.csv. (llvmpipe takes about 3 minutes per GPU run here, E = 1e7 2.5 times that.)
// --quick runs E = 1e6 and 1e7 only for energy. --backends picks among cpu, gpu-float, gpu-double
// (the three by default) and gpu-full-double.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_scenes.h"
#include "core/atomic_file.h"
#include "gpu/context.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"

namespace {

namespace fs = std::filesystem;
using namespace ts::sim;
using namespace ts::scene;
using Clock = std::chrono::steady_clock;

struct Backend {
  std::string name;  // cpu, gpu-float, gpu-double
  bool gpu = false;
  Precision precision = Precision::Float;
};
// gpu-full-double (the contact kernel in double too) runs only when named with --backends: it is the
// yardstick of the mixed-precision gpu-double, not a user-facing choice.
const std::vector<Backend> kBackends = {{"cpu", false, Precision::Float},
                                        {"gpu-float", true, Precision::Float},
                                        {"gpu-double", true, Precision::Double},
                                        {"gpu-full-double", true, Precision::FullDouble}};

// The scene `name` with its material's E replaced and dt = factor x the automatic bound.
Scene variant(const std::string& name, double youngs_modulus, double dt_factor, World* world, double* bound) {
  Scene scene = load_scene(ts::bench::reference_scene(name));
  for (Material& m : scene.materials) m.youngs_modulus = youngs_modulus;
  *world = make_world(scene);
  *bound = scene_time_step_bound(scene, *world).recommended;
  scene.simulation.dt = dt_factor * *bound;
  scene.simulation.step.dt = scene.simulation.dt;
  scene.simulation.step.check_energy = false;  // dt = 2 x the bound is measured, not stopped
  return scene;
}

// Mechanical energy of `world` as it stands (J): kinetic + potential + the Hertz springs of its
// contacts, the last from one CPU-reference force evaluation on a copy.
struct Probe {
  double mechanical = 0, max_overlap_ratio = 0;
};
Probe probe(const World& world, const StepSettings& settings) {
  World copy = world;
  CpuStepper stepper(copy, settings);
  const Energy before = energy(world);
  const StepStats s = stepper.step(copy);  // its elastic energy is the state's, before integrating
  return {before.total() + s.elastic_energy, s.max_overlap_ratio};
}

// Potential energy of the dynamic bodies above the floor z = 0 (J): the energy scale of the drop.
double drop_energy(const World& world) {
  double e = 0;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] == MotionType::Dynamic) {
      e += -world.gravity.z() * world.bodies.position[b].z() / world.bodies.inverse_mass[b];
    }
  }
  return e;
}

std::vector<Backend> pick_backends(const std::string& list) {
  std::vector<Backend> out;
  std::stringstream items(list);
  for (std::string name; std::getline(items, name, ',');) {
    const auto it = std::find_if(kBackends.begin(), kBackends.end(), [&](const Backend& b) { return b.name == name; });
    if (it == kBackends.end()) throw std::runtime_error("--backends: unknown backend " + name);
    out.push_back(*it);
  }
  return out;
}

std::string energy_runs(ts::gpu::Context& context, const std::vector<Backend>& backends,
                        const std::vector<double>& moduli) {
  std::string csv = "backend,E_Pa,dt_factor,dt_s,steps,max_overlap_ratio,max_energy_error,final_energy_error,seconds\n";
  for (double e : moduli) {
    for (double factor : {0.5, 1.0, 2.0}) {
      for (const Backend& backend : backends) {
        World world;
        double bound = 0;
        const Scene scene = variant("elastic_box.toml", e, factor, &world, &bound);
        const StepSettings& settings = scene.simulation.step;
        const auto steps = static_cast<std::int64_t>(std::ceil(scene.simulation.duration / settings.dt));
        const std::int64_t sample_every = std::max<std::int64_t>(1, steps / 400);
        const double e0 = probe(world, settings).mechanical, scale = drop_energy(world);
        double max_overlap = 0, max_error = 0, error = 0;
        std::unique_ptr<CpuStepper> cpu;
        std::unique_ptr<GpuStepper> gpu;
        if (backend.gpu) {
          gpu = std::make_unique<GpuStepper>(context, world, settings, backend.precision);
        } else {
          cpu = std::make_unique<CpuStepper>(world, settings);
        }
        const auto start = Clock::now();
        for (std::int64_t s = 1; s <= steps; ++s) {
          if (gpu) {
            gpu->step(1);
            max_overlap = std::max(max_overlap, gpu->statistics().max_overlap_ratio);
          } else {
            max_overlap = std::max(max_overlap, cpu->step(world).max_overlap_ratio);
          }
          if (s % sample_every == 0 || s == steps) {
            if (gpu) gpu->download(world);
            error = std::abs(probe(world, settings).mechanical - e0) / scale;
            max_error = std::max(max_error, error);
          }
        }
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        std::fprintf(stderr, "energy %s E=%g dt=%gx: overlap %.4f r, energy error %.3g (final %.3g), %.1f s\n",
                     backend.name.c_str(), e, factor, max_overlap, max_error, error, seconds);
        csv += fmt::format("{},{:g},{:g},{:.4g},{},{:.5g},{:.4g},{:.4g},{:.1f}\n", backend.name, e, factor,
                           settings.dt, steps, max_overlap, max_error, error, seconds);
      }
    }
  }
  return csv;
}

std::string pile_runs(ts::gpu::Context& context, const std::vector<Backend>& backends,
                      const std::vector<double>& moduli, const fs::path& out) {
  std::string csv = "backend,E_Pa,dt_factor,dt_s,steps,grains,max_overlap_ratio_at_outputs,seconds,heap_file\n";
  for (double e : moduli) {
    for (double factor : {1.0, 2.0}) {
      for (const Backend& backend : backends) {
        World world;
        double bound = 0;
        Scene scene = variant("heap.toml", e, factor, &world, &bound);
        scene.emitters.at(0).count = 150;
        scene.boundaries.at(0).size = Eigen::Vector2d(0.06, 0.06);  // m: the heap's foot is about 4 cm wide
        scene.simulation.duration = 0.5;
        scene.output.every = 50;
        scene.output.ply = false;
        scene.output.csv = false;
        double max_overlap = 0;
        World last;
        RunHooks hooks;
        hooks.on_output = [&](const World& w, const StepStats& s, std::int64_t) {
          max_overlap = std::max(max_overlap, s.max_overlap_ratio);
          last = w;
        };
        std::function<std::unique_ptr<Stepper>(const StepSettings&)> make;
        if (backend.gpu) {
          make = [&](const StepSettings& s) -> std::unique_ptr<Stepper> {
            return std::make_unique<GpuStepper>(context, s, backend.precision, false);
          };
        }
        const std::string name = fmt::format("heap_{}_E{:g}_dt{:g}", backend.name, e, factor);
        const auto start = Clock::now();
        const RunResult r = run_scene(scene, out / "runs" / name, hooks, make);
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        ts::write_file_atomically(out / (name + ".csv"), ts::bench::grain_centres_csv(last));
        std::fprintf(stderr, "pile %s E=%g dt=%gx: %zu grains, overlap %.4f r, %.1f s\n", backend.name.c_str(), e,
                     factor, r.grains, max_overlap, seconds);
        csv += fmt::format("{},{:g},{:g},{:.4g},{},{},{:.5g},{:.1f},{}.csv\n", backend.name, e, factor, r.dt, r.steps,
                           r.grains, max_overlap, seconds, name);
      }
    }
  }
  return csv;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR [energy|pile|all] [--quick] [--backends LIST]\n", argv[0]);
    return 2;
  }
  try {
    const fs::path out = argv[1];
    std::string what = "all";
    bool quick = false;
    std::vector<Backend> backends = pick_backends("cpu,gpu-float,gpu-double");
    for (int i = 2; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--quick") {
        quick = true;
      } else if (arg == "--backends" && i + 1 < argc) {
        backends = pick_backends(argv[++i]);
      } else if (arg == "energy" || arg == "pile" || arg == "all") {
        what = arg;
      } else {
        throw std::runtime_error("unknown argument " + arg + " (expected energy, pile, all, --quick or --backends LIST)");
      }
    }
    fs::create_directories(out);
    ts::gpu::Context context;
    ts::write_file_atomically(out / "renderer.txt", context.summary() + "\n");
    if (what == "energy" || what == "all") {
      const std::vector<double> moduli = quick ? std::vector<double>{1e6, 1e7} : std::vector<double>{1e6, 1e7, 1e8};
      ts::write_file_atomically(out / "energy.csv", energy_runs(context, backends, moduli));
    }
    if (what == "pile" || what == "all") {
      ts::write_file_atomically(out / "pile.csv", pile_runs(context, backends, {1e6}, out));
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
