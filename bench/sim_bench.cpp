// Cundall number (grain time steps per second) of the GPU pipeline and of the CPU reference on the
// same scenes, in one run, as ratios, from 1k to 1M grains; memory per grain of both. Usage:
//   tetrasand_bench_sim [--grains 1000,8000,64000,512000,1000000] [--seconds 2] [--min-steps 2]
//                       [--cpu-min-steps N] [--precision float|double|full-double (a list)] [--csv FILE]
//                       [--timings] [--bonded 256,2048] [--bonded-csv FILE] [--scene bed|plough]
//                       [--plough-speed 0.5] [--skip-cpu]
// --cpu-min-steps: the CPU reference's own minimum (default --min-steps), so a device run can time 10 GPU
// steps a size without spending its time cap on 10 CPU steps of 4M grains. --timings prints each engine's
// timing_report() (per-kernel GPU times, the contact lists' skin, builds and candidates) on stderr.
// The scene of every size is the settled bed of bench/bench_scenes.h (reference/bed_tile.toml copied
// side by side), so each size sees the same contacts per grain. scripts/bench.sh sim plots the CSV.
// With two precisions the CPU reference is measured once per size and each GPU precision gets a row.
// double is the mixed-precision pipeline of `--precision double`; full-double keeps the contact kernel
// in double too (sim::Precision::FullDouble), to time what the mixed pipeline saves.
// The CSV is rewritten (atomically) after every size, so a run stopped at its time cap keeps its rows.
// --scene plough measures a scene that moves instead (bench_scenes.h ploughed_bed: the same bed with a
// kinematic blade driven through it at --plough-speed m/s), where the contact lists are rebuilt every
// few tens of steps, so its rate includes their builds (--timings says how many, and what they cost).
// Its grain count is the bed's grains left after the blade's slot; the blade's spheres are not counted.
// --skip-cpu leaves the CPU reference out (its columns and the contacts per grain 0, the ratio nan): at 4M
// grains its world copy and stepper would double the memory the GPU measurement needs, and take its time.
// --bonded 256,2048 (sphere counts, default none) adds, after the grain rows, a row per size of
// bonded spheres (bench_scenes.h bonded_block: breakable-prop spheres resting on a floor, the bond law
// in both steppers, issue 48): sphere-steps per second of both, and the memory per bond of both (GPU:
// its buffers with the bonds less the same world's without; CPU: the bonds' arrays and the step's load
// scratch, counted from their element sizes). --bonded-csv FILE writes those rows (atomically).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_scenes.h"
#include "core/atomic_file.h"
#include "gpu/context.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::vector<std::uint32_t> grains{1000, 8000, 64000, 512000, 1000000};
  double seconds = 2.0;  // wall time per measurement (at least min_steps steps)
  int min_steps = 2;
  int cpu_min_steps = 0;  // 0: min_steps
  std::vector<ts::sim::Precision> precisions{ts::sim::Precision::Float};
  std::string csv;
  bool timings = false;  // per-kernel GPU times and host round trips of each size, on stderr
  std::vector<std::uint32_t> bonded;  // sphere counts of the bonded rows
  std::string bonded_csv;
  std::string scene = "bed";  // bed (settled) or plough (moving)
  double plough_speed = 0.5;  // m/s
  bool skip_cpu = false;      // GPU rows only
};

std::vector<std::uint32_t> parse_counts(const std::string& text) {
  std::vector<std::uint32_t> out;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) out.push_back(static_cast<std::uint32_t>(std::stoul(item)));
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error("missing value after " + arg);
      return argv[++i];
    };
    if (arg == "--grains") {
      o.grains = parse_counts(next());
    } else if (arg == "--seconds") {
      o.seconds = std::stod(next());
    } else if (arg == "--min-steps") {
      o.min_steps = std::max(1, std::stoi(next()));
    } else if (arg == "--cpu-min-steps") {
      o.cpu_min_steps = std::max(1, std::stoi(next()));
    } else if (arg == "--precision") {
      o.precisions.clear();
      std::stringstream list(next());
      for (std::string p; std::getline(list, p, ',');) {
        if (p != "float" && p != "double" && p != "full-double")
          throw std::runtime_error("--precision: expected float, double or full-double, got " + p);
        o.precisions.push_back(p == "double"        ? ts::sim::Precision::Double
                               : p == "full-double" ? ts::sim::Precision::FullDouble
                                                    : ts::sim::Precision::Float);
      }
    } else if (arg == "--csv") {
      o.csv = next();
    } else if (arg == "--bonded") {
      o.bonded = parse_counts(next());
    } else if (arg == "--bonded-csv") {
      o.bonded_csv = next();
    } else if (arg == "--scene") {
      o.scene = next();
      if (o.scene != "bed" && o.scene != "plough")
        throw std::runtime_error("--scene: expected bed or plough, got " + o.scene);
    } else if (arg == "--plough-speed") {
      o.plough_speed = std::stod(next());
      if (!(o.plough_speed > 0 && o.plough_speed <= 10))
        throw std::runtime_error("--plough-speed: expected a speed in m/s within (0, 10], got " +
                                 std::string(argv[i]));
    } else if (arg == "--skip-cpu") {
      o.skip_cpu = true;
    } else if (arg == "--timings") {
      o.timings = true;
    } else {
      throw std::runtime_error("unknown option " + arg);
    }
  }
  return o;
}

// Resident set size of this process (bytes), from /proc/self/statm.
double resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  double pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

struct Rate {
  double steps_per_second = 0;
  int steps = 0;  // timed steps
};

// One warm-up call (shader compilation, first allocations), then calls of `batch` steps until
// `seconds` of wall time and `min_steps` steps have passed.
template <typename StepFn, typename SyncFn>
Rate measure(StepFn step, SyncFn sync, double seconds, int min_steps, int batch) {
  step(1);
  sync();
  Rate r;
  const auto start = Clock::now();
  double elapsed = 0.0;
  while (elapsed < seconds || r.steps < min_steps) {
    step(batch);
    sync();
    r.steps += batch;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  }
  r.steps_per_second = r.steps / elapsed;
  return r;
}

// One size: the CPU reference once, then one GPU measurement per precision asked for.
struct Row {
  std::size_t grains = 0, particles = 0;
  double contacts_per_grain = 0;
  double dt = 0;  // s
  Rate cpu;
  double cpu_bytes_per_grain = 0;
  std::vector<Rate> gpu;                    // one per Options::precisions
  std::vector<double> gpu_bytes_per_grain;  // likewise
};

Row measure_size(ts::gpu::Context& context, std::uint32_t requested, const Options& options) {
  const ts::bench::BenchWorld bed = options.scene == "plough"
                                        ? ts::bench::ploughed_bed(requested, options.plough_speed)
                                        : ts::bench::settled_bed(requested);
  Row row;
  row.grains = static_cast<std::size_t>(std::count(
      bed.world.bodies.motion.begin(), bed.world.bodies.motion.end(), ts::sim::MotionType::Dynamic));
  row.particles = bed.world.particles.size();
  row.dt = bed.settings.dt;
  const int batch = std::clamp(static_cast<int>(200000 / row.grains), 1, 100);
  if (!options.skip_cpu) {
    // CPU first, so the resident-memory growth it causes is not memory the GPU stepper freed.
    const double before = resident_bytes();
    ts::sim::World world = bed.world;
    ts::sim::CpuStepper cpu(world, bed.settings);
    ts::sim::StepStats stats;
    row.cpu = measure(
        [&](int n) {
          for (int s = 0; s < n; ++s) stats = cpu.step(world);
        },
        [] {}, options.seconds, options.cpu_min_steps > 0 ? options.cpu_min_steps : options.min_steps,
        std::max(1, batch / 10));
    if (options.timings) fmt::print(stderr, "{} grains, CPU reference:\n{}", row.grains, cpu.timing_report());
    row.cpu_bytes_per_grain = (resident_bytes() - before) / static_cast<double>(row.grains);
    row.contacts_per_grain = static_cast<double>(stats.contacts + stats.wall_contacts) / static_cast<double>(row.grains);
  }
  for (const ts::sim::Precision precision : options.precisions) {
    ts::sim::GpuStepper gpu(context, bed.world, bed.settings, precision, options.timings);
    row.gpu.push_back(measure([&](int n) { gpu.step(n); }, [&] { context.finish(); }, options.seconds,
                              options.min_steps, batch));
    if (options.timings) fmt::print(stderr, "{} grains:\n{}", row.grains, gpu.timing_report());
    row.gpu_bytes_per_grain.push_back(static_cast<double>(gpu.gpu_bytes()) / static_cast<double>(row.grains));
  }
  return row;
}

const char* precision_name(ts::sim::Precision p);

// Bytes a bond takes in the CPU reference: its BondSet entries, its load scratch of a step
// (sim/cpu_bonds.cpp) and its two entries in the lists' bonded partners.
double cpu_bytes_per_bond() {
  return 2 * sizeof(std::uint32_t) + sizeof(std::uint16_t) + 2 * sizeof(double) + sizeof(std::uint8_t) +
         sizeof(ts::sim::BondState<double>) + sizeof(double) + sizeof(ts::sim::BondLoad<double>) +
         2 * sizeof(std::uint32_t);
}

// One size of bonded spheres: sphere-steps per second of the CPU reference and of each GPU precision,
// and bytes per bond. Returns its CSV rows.
std::string measure_bonded(ts::gpu::Context& context, std::uint32_t requested, const Options& options) {
  const ts::bench::BondedBlock block = ts::bench::bonded_block(requested);
  ts::sim::StepSettings settings;
  settings.dt = block.dt;
  settings.integrator = ts::sim::Integrator::SemiImplicitEuler;
  const double spheres = static_cast<double>(block.world.particles.size());
  const double bonds = static_cast<double>(block.world.bonds.size());
  const int batch = std::clamp(static_cast<int>(200000 / spheres), 1, 100);
  ts::sim::World world = block.world;
  ts::sim::CpuStepper cpu(world, settings);
  const Rate c = measure(
      [&](int n) {
        for (int s = 0; s < n; ++s) cpu.step(world);
      },
      [] {}, options.seconds, options.cpu_min_steps > 0 ? options.cpu_min_steps : options.min_steps,
      std::max(1, batch / 10));
  std::string rows;
  for (const ts::sim::Precision precision : options.precisions) {
    ts::sim::GpuStepper gpu(context, block.world, settings, precision, options.timings);
    const Rate g = measure([&](int n) { gpu.step(n); }, [&] { context.finish(); }, options.seconds, options.min_steps,
                           batch);
    if (options.timings) fmt::print(stderr, "{} bonded spheres:\n{}", spheres, gpu.timing_report());
    ts::sim::World unbonded = block.world;
    unbonded.bonds = {};
    unbonded.bond_materials.clear();
    const ts::sim::GpuStepper plain(context, unbonded, settings, precision);
    const double gpu_per_bond = (static_cast<double>(gpu.gpu_bytes()) - static_cast<double>(plain.gpu_bytes())) / bonds;
    const double gs = g.steps_per_second * spheres, cs = c.steps_per_second * spheres;
    fmt::print("bonded spheres {:>6} ({} bonds): GPU {} {:.3g} sphere-steps/s ({} steps), CPU reference {:.3g} "
               "sphere-steps/s ({} steps), ratio {:.2f}; memory per bond GPU {:.0f} B, CPU {:.0f} B\n",
               spheres, bonds, precision_name(precision), gs, g.steps, cs, c.steps, gs / cs, gpu_per_bond,
               cpu_bytes_per_bond());
    std::fflush(stdout);
    rows += fmt::format("{},{},{:.4g},{},{:.5g},{},{:.5g},{:.4f},{:.1f},{:.1f},{},\"{}\"\n", spheres, bonds, block.dt,
                        g.steps, gs, c.steps, cs, gs / cs, gpu_per_bond, cpu_bytes_per_bond(),
                        precision_name(precision), context.summary());
  }
  return rows;
}

const char* precision_name(ts::sim::Precision p) {
  return p == ts::sim::Precision::Double ? "double" : p == ts::sim::Precision::FullDouble ? "full-double" : "float";
}

// The printed line and the CSV row of one size and precision k.
std::string report_row(const Row& r, std::size_t k, ts::sim::Precision precision, const std::string& renderer,
                       const std::string& scene) {
  const double g = r.gpu[k].steps_per_second * static_cast<double>(r.grains);
  const double c = r.cpu.steps_per_second * static_cast<double>(r.grains);
  const double ratio = c > 0 ? g / c : std::nan("");  // --skip-cpu: no CPU rate
  fmt::print(
      "{} grains {:>8}: {:.1f} contacts/grain; GPU {} {:.3g} grain-steps/s ({} steps), CPU reference {:.3g} "
      "grain-steps/s ({} steps), ratio {:.2f}; memory per grain GPU {:.0f} B, CPU {:.0f} B\n",
      scene, r.grains, r.contacts_per_grain, precision_name(precision), g, r.gpu[k].steps, c, r.cpu.steps,
      ratio, r.gpu_bytes_per_grain[k], r.cpu_bytes_per_grain);
  std::fflush(stdout);
  return fmt::format("{},{},{:.3f},{:.4g},{},{:.5g},{},{:.5g},{:.4f},{:.1f},{:.1f},{},\"{}\",{}\n", r.grains,
                     r.particles, r.contacts_per_grain, r.dt, r.gpu[k].steps, g, r.cpu.steps, c, ratio,
                     r.gpu_bytes_per_grain[k], r.cpu_bytes_per_grain, precision_name(precision), renderer,
                     scene);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    ts::gpu::Context context;
    fmt::print(stderr, "renderer: {}\n", context.summary());
    std::string csv =
        "grains,particles,contacts_per_grain,dt_s,gpu_steps,gpu_grain_steps_per_s,cpu_steps,"
        "cpu_grain_steps_per_s,gpu_over_cpu,gpu_bytes_per_grain,cpu_bytes_per_grain,precision,renderer,scene\n";
    for (std::uint32_t requested : options.grains) {
      const Row r = measure_size(context, requested, options);
      for (std::size_t k = 0; k < options.precisions.size(); ++k)
        csv += report_row(r, k, options.precisions[k], context.summary(), options.scene);
      if (!options.csv.empty()) ts::write_file_atomically(options.csv, csv);
    }
    std::string bonded_csv =
        "spheres,bonds,dt_s,gpu_steps,gpu_sphere_steps_per_s,cpu_steps,cpu_sphere_steps_per_s,gpu_over_cpu,"
        "gpu_bytes_per_bond,cpu_bytes_per_bond,precision,renderer\n";
    for (std::uint32_t requested : options.bonded) {
      bonded_csv += measure_bonded(context, requested, options);
      if (!options.bonded_csv.empty()) ts::write_file_atomically(options.bonded_csv, bonded_csv);
    }
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
}
