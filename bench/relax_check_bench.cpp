// The cost of the sampler's convergence check (RelaxSettings::check_every, sampler/gpu_relaxer.h):
// the reduction and its read-back, the one host-GPU round trip of the relaxation loop, against the
// iterations it follows. On a sphere seeded at random, with the tolerance at 0 so every run makes
// all its iterations, it times (best of --repeats) M and 2M iterations with one check, which gives
// the time of an iteration; M iterations checked every iteration, whose excess over the single
// check divided by the M - 1 extra checks is the time of a check; and M iterations checked every K
// for each K of --every. Prints one JSON line per K: check_share = t_check / (K t_iteration), the
// fraction the checks add to the loop, and measured_excess = t(K) / t(one check) - 1, the same
// seen directly (noisier: a few checks against the whole run).
//
// Criterion, written before the first run (issue 16): at the default K = 10 the check adds under
// 2 % to the relaxation at 10k and 100k particles on llvmpipe; otherwise the default is raised to
// the smallest K of --every that meets it at both counts. A hardware GPU adds the pipeline drain
// that llvmpipe (whose dispatches run to completion) does not have; that part is not measured here.
// Times are the process's CPU time (llvmpipe's threads are the process's), best of --repeats: on a
// shared machine wall time measures the other processes too (first run, load 11 on 2 cores: the
// same work took 3.0 s and 6.2 s of wall time).
//   tetrasand_bench_relax_check [--particles N] [--iterations M] [--repeats R] [--every K1,K2,...]
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
  int repeats = 3;
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
    } else if (a == "--repeats") {
      o.repeats = std::stoi(value);
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

// Best CPU time [s] of `repeats` relaxations of the seeds, M iterations checked every K.
double best_time(ts::sampler::GpuRelaxer& relaxer, const Setup& s, int iterations, int every, int repeats) {
  ts::sampler::RelaxSettings settings = s.settings;
  settings.max_iterations = iterations;
  settings.check_every = every;
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    std::vector<Eigen::Vector3f> positions = s.seeds;
    const double start = cpu_seconds();
    relaxer.relax(positions, settings);
    best = std::min(best, cpu_seconds() - start);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    ts::gpu::Context context;
    Setup s = make_setup(context, o.particles);
    ts::sampler::GpuRelaxer relaxer(context, std::move(s.field));
    const int m = o.iterations;
    best_time(relaxer, s, m, m, 1);  // warm-up: shaders, buffers
    const double one_check = best_time(relaxer, s, m, m, o.repeats);
    const double iteration = (best_time(relaxer, s, 2 * m, 2 * m, o.repeats) - one_check) / m;
    const double check = (best_time(relaxer, s, m, 1, o.repeats) - one_check) / (m - 1);
    for (int k : o.every) {
      const double t = best_time(relaxer, s, m, k, o.repeats);
      fmt::print(
          "{{\"particles\": {}, \"iterations\": {}, \"every\": {}, \"cpu_seconds\": {:.4f}, "
          "\"one_check_cpu_seconds\": {:.4f}, \"iteration_ms\": {:.4f}, \"check_ms\": {:.4f}, "
          "\"check_share\": {:.5f}, \"measured_excess\": {:.5f}, \"renderer\": \"{}\"}}\n",
          o.particles, m, k, t, one_check, 1e3 * iteration, 1e3 * check, check / (k * iteration),
          t / one_check - 1.0, context.renderer());
      std::fflush(stdout);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tetrasand_bench_relax_check: %s\n", e.what());
    return 2;
  }
}
