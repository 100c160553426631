// The coverage certificate against the probe pass on one body, side by side in one process: the
// certificate (GPU, sampler/gpu_coverage_certificate.h), its CPU twin (sampler/cpu_coverage_certificate.h,
// all cores) and the sampler's statistical pass (1M random surface probes, CPU on all cores) on the
// particles as the body stores them, then an independent probe check (10M probes, another seed)
// whose deepest point must never lie beyond the certified bound, nor beyond r when the body is
// certified; the two certificates must agree (same verdict, bounds within the floor of each other).
// Prints one JSON object (bench/certificate_bench.py collects them into docs/benchmarks.md, section
// certificate). Exit 1 when a check fails.
//   tetrasand_bench_certificate MESH BODY.json [--probes N] [--independent N] [--seed S]
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "body/body_file.h"
#include "core/mesh_io.h"
#include "gpu/context.h"
#include "sampler/gpu_coverage_certificate.h"
#include "sampler/cpu_coverage_certificate.h"
#include "sampler/sampling_quality.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Options {
  std::string mesh, body;
  std::size_t probes = 1'000'000, independent = 10'000'000;
  std::uint64_t seed = 424242;  // not one the sampler uses (seed + 1000 k + 500)
};

Options parse(int argc, char** argv) {
  Options o;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return std::string(argv[++i]);
    };
    if (a == "--probes") {
      o.probes = std::stoull(next());
    } else if (a == "--independent") {
      o.independent = std::stoull(next());
    } else if (a == "--seed") {
      o.seed = std::stoull(next());
    } else {
      positional.push_back(a);
    }
  }
  if (positional.size() != 2)
    throw std::runtime_error("usage: tetrasand_bench_certificate MESH BODY.json [options]");
  o.mesh = positional[0];
  o.body = positional[1];
  return o;
}

// The certificate's figures and time, the certifier's set-up (triangle upload, shaders) apart.
nlohmann::json certificate_figures(ts::gpu::Context& context, const ts::TriangleMesh& mesh,
                                   const std::vector<Eigen::Vector3f>& centres, double r) {
  auto t = Clock::now();
  ts::sampler::GpuCoverageCertifier certifier(context, mesh);
  const double setup = since(t);
  t = Clock::now();
  const ts::sampler::CoverageCertificate c = certifier.certify(centres, r);
  const double seconds = since(t);
  return {{"certificate_s", seconds},
          {"certificate_setup_s", setup},
          {"certified", c.covered},
          {"bound_over_r", c.covering_bound / r},
          {"lower_over_r", c.covering_lower / r},
          {"uncovered", c.uncovered},
          {"uncovered_area", c.uncovered_area},
          {"evaluated", c.evaluated},
          {"levels", c.levels},
          {"margin_over_r", c.margin / r},
          {"budget_reached", c.budget_reached},
          {"tiles", c.tiles},
          {"tiles_redone", c.tiles_redone}};
}

// The CPU certifier's figures and time, keyed "cpu_...".
nlohmann::json cpu_certificate_figures(const ts::TriangleMesh& mesh,
                                       const std::vector<Eigen::Vector3f>& centres, double r,
                                       ts::sampler::CoverageCertificate* result) {
  auto t = Clock::now();
  ts::sampler::CpuCoverageCertifier certifier(mesh);
  const double setup = since(t);
  t = Clock::now();
  *result = certifier.certify(centres, r);
  const double seconds = since(t);
  const ts::sampler::CoverageCertificate& c = *result;
  return {{"cpu_certificate_s", seconds},
          {"cpu_certificate_setup_s", setup},
          {"cpu_certified", c.covered},
          {"cpu_bound_over_r", c.covering_bound / r},
          {"cpu_lower_over_r", c.covering_lower / r},
          {"cpu_uncovered", c.uncovered},
          {"cpu_uncovered_area", c.uncovered_area},
          {"cpu_evaluated", c.evaluated},
          {"cpu_levels", c.levels},
          {"cpu_margin_over_r", c.margin / r}};
}

double probe_pass(const ts::TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& centres,
                  std::size_t probes, std::uint64_t seed, double* seconds) {
  ts::sampler::CoverageSettings settings;
  settings.probes = probes;
  settings.seed = seed;
  const auto t = Clock::now();
  const double c = ts::sampler::measure_coverage(mesh, centres, settings).covering_radius;
  *seconds = since(t);
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    const ts::TriangleMesh mesh = ts::load_mesh(o.mesh);
    const ts::body::ParticleBody body = ts::body::read_body(o.body);
    const std::vector<Eigen::Vector3f> centres(
        body.positions.begin(), body.positions.end() - static_cast<std::ptrdiff_t>(body.interior_count));
    const double r = body.particle_radius;
    ts::gpu::Context context;
    nlohmann::json out = certificate_figures(context, mesh, centres, r);
    ts::sampler::CoverageCertificate cpu;
    out.update(cpu_certificate_figures(mesh, centres, r, &cpu));
    double probe_s = 0.0, independent_s = 0.0;
    const double c_probes = probe_pass(mesh, centres, o.probes, o.seed, &probe_s);
    const double c_independent = probe_pass(mesh, centres, o.independent, o.seed + 1, &independent_s);
    out["particles"] = centres.size();
    out["radius"] = r;
    out["triangles"] = mesh.triangle_count();
    out["renderer"] = context.summary();
    out["probes"] = o.probes;
    out["probes_s"] = probe_s;
    out["probes_c_over_r"] = c_probes / r;
    out["independent_probes"] = o.independent;
    out["independent_s"] = independent_s;
    out["independent_c_over_r"] = c_independent / r;
    // The criterion (docs/benchmarks.md, certificate): no probe beyond the bound; none beyond r if certified.
    const bool holds = c_independent / r <= out["bound_over_r"].get<double>() &&
                       c_probes / r <= out["bound_over_r"].get<double>() &&
                       (!out["certified"].get<bool>() || c_independent <= r);
    out["criterion_holds"] = holds;
    // Criterion 6 (bench/certificate_criteria.md): the CPU certificate gives the GPU's verdict, a bound
    // within the floor (max(r, c) / 64, c at least either lower figure) plus both margins of the
    // GPU's, and no probe lies beyond it, nor beyond r when it certifies.
    const double gpu_bound = out["bound_over_r"].get<double>() * r;
    const double c_at_least = std::max(out["lower_over_r"].get<double>() * r, cpu.covering_lower);
    const double tolerance =
        std::max(r, c_at_least) / 64.0 + out["margin_over_r"].get<double>() * r + cpu.margin;
    out["cpu_bound_difference_over_floor"] = (cpu.covering_bound - gpu_bound) / (r / 64.0);
    const bool cpu_agrees = cpu.covered == out["certified"].get<bool>() &&
                            std::abs(cpu.covering_bound - gpu_bound) <= tolerance &&
                            c_independent <= cpu.covering_bound && c_probes <= cpu.covering_bound &&
                            (!cpu.covered || c_independent <= r);
    out["cpu_agrees"] = cpu_agrees;
    fmt::print("{}\n", out.dump());
    return holds && cpu_agrees ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tetrasand_bench_certificate: %s\n", e.what());
    return 2;
  }
}
