// The cost of the sampler's convergence check (RelaxSettings::check_every, sampler/gpu_relaxer.h):
// the reduction and its read-back, the one host-GPU round trip of the relaxation loop, against the
// iterations it follows. On a sphere seeded at random, with the tolerance at 0 so the run makes all
// its --iterations, one relaxation checked every 10 iterations is timed kernel by kernel by the
// relaxer's timer queries (--timings): t_check = the reduction's time per call, t_iteration = the
// grid build and the relaxation kernel per iteration. Prints one JSON line per K of --every:
// check_share = t_check / (K t_iteration), the fraction the checks add to the loop.
//
// Criterion, written before the first run (issue 16): at the default K = 10 the check adds under
// 2 % to the relaxation at 10k and 100k particles on llvmpipe; otherwise the default is raised to
// the smallest K of --every that meets it at both counts. A hardware GPU adds the pipeline drain
// that llvmpipe (whose dispatches run to completion) does not have; that part is not measured here,
// nor is the host's copy of the (n + 255) / 256 partial sums (16 bytes each) it reads.
// Why timer queries and not the run's time: on a shared machine wall time, and even CPU time,
// measure the other processes too, far more than the few per cent sought (first runs, load 11 on 2
// cores, 10k particles, 50 iterations: 3.0 s and 6.2 s of wall time, and 2.5 s of CPU time with
// 3 checks against 2.0 s with 5).
//   tetrasand_bench_relax_check [--particles N] [--iterations M] [--every K1,K2,...]
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/primitives.h"
#include "gpu/context.h"
#include "sampler/gpu_relaxer.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"

namespace {

// CPU time of this process and its threads [s].
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Options {
  std::size_t particles = 10'000;
  int iterations = 100;
  std::vector<int> every{5, 10, 20};
};

std::vector<int> parse_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stoi(item));
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
    const std::string value = argv[++i];
    if (a == "--particles") {
      o.particles = std::stoull(value);
    } else if (a == "--iterations") {
      o.iterations = std::stoi(value);
    } else if (a == "--every") {
      o.every = parse_list(value);
    } else {
      throw std::runtime_error("unknown option " + a);
    }
  }
  return o;
}

// A unit sphere's sparse field at half the hexagonal spacing of `count` particles (the sampler's
// voxel), the seeds, and settings that keep every run to its full iteration count.
struct Setup {
  ts::sdf::GridSpec spec;
  ts::sdf::SparseField field;
  std::vector<Eigen::Vector3f> seeds;
  ts::sampler::RelaxSettings settings;
};

Setup make_setup(ts::gpu::Context& context, std::size_t count) {
  const ts::TriangleMesh sphere = ts::make_icosphere(1.0, 5);
  const double spacing =
      std::sqrt(2.0 * 4.0 * std::numbers::pi / (std::sqrt(3.0) * static_cast<double>(count)));
  ts::sdf::SdfSettings grid;
  grid.voxel_size = spacing / 2.0;
  grid.band = 5.0;
  Setup s;
  s.spec = ts::sdf::make_grid(ts::bounding_box(sphere), grid);
  ts::sdf::ScanConvertOptions scan;
  scan.index_space_grid = true;
  scan.band = grid.band;
  const auto converted =
      ts::sdf::scan_convert(context, sphere, ts::sdf::compute_pseudonormals(sphere), s.spec, scan);
  s.field = ts::sdf::SparseField(*converted.grid, s.spec, scan.band);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss;
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d p = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    s.seeds.push_back((p - s.spec.origin).cast<float>());
  }
  s.settings.spacing = spacing;
  s.settings.band_limit = 4.5 * grid.voxel_size;
  s.settings.tolerance = 0.0;
  return s;
}

// Per-kernel GPU time [ms] and calls, from the relaxer's --timings table ("name calls ms share").
struct KernelTimes {
  double check_ms = 0.0, iterations_ms = 0.0;  // the reduction; everything but it and the projection
  int checks = 0;
};

KernelTimes parse_report(const std::string& report) {
  KernelTimes t;
  std::istringstream lines(report);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    std::string name;
    int calls = 0;
    double ms = 0.0;
    if (!(fields >> name >> calls >> ms) || name == "total") continue;
    if (name == "sampler/reduce_steps.comp") {
      t.check_ms += ms, t.checks += calls;
    } else if (name != "sampler/project.comp") {
      t.iterations_ms += ms;
    }
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    ts::gpu::Context context;
    Setup s = make_setup(context, o.particles);
    ts::sampler::GpuRelaxer relaxer(context, std::move(s.field), /*timings=*/true);
    ts::sampler::RelaxSettings settings = s.settings;
    settings.max_iterations = o.iterations;
    settings.check_every = 10;
    std::vector<Eigen::Vector3f> positions = s.seeds;
    const double start = cpu_seconds();
    const ts::sampler::RelaxStats stats = relaxer.relax(positions, settings);
    const double cpu = cpu_seconds() - start;
    const KernelTimes t = parse_report(relaxer.timing_report());
    const double iteration = t.iterations_ms / stats.iterations, check = t.check_ms / std::max(t.checks, 1);
    for (int k : o.every) {
      fmt::print(
          "{{\"particles\": {}, \"iterations\": {}, \"every\": {}, \"iteration_ms\": {:.4f}, \"check_ms\": "
          "{:.4f}, "
          "\"check_share\": {:.5f}, \"relax_cpu_seconds\": {:.3f}, \"renderer\": \"{}\"}}\n",
          o.particles, stats.iterations, k, iteration, check, check / (k * iteration), cpu,
          context.renderer());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tetrasand_bench_relax_check: %s\n", e.what());
    return 2;
  }
}
