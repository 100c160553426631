// `tetrasand sample MESH`: the main job. A closed mesh becomes a particle rigid body.
#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/mesh_io.h"
#include "core/mesh_report.h"
#include "sampler/particle_body.h"
#include "sampler/sample_mesh.h"

namespace ts::app {

Runner add_sample_command(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand("sample", "Convert a closed mesh into a particle rigid body (NAME.particles.ply + NAME.body.json)");
  struct Options {
    std::string mesh, output = ".";
    double radius = 0, coverage = 1.0, grain_radius = 0, voxel = 0, density = 1000.0, scale = 1.0;
    std::size_t count = 0, probes = 1'000'000;
    std::uint64_t seed = 1;
    int rounds = 8;
    bool json = false, timings = false, allow_open = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("MESH", o->mesh, "Closed, consistently oriented triangle mesh")->required();
  cmd->add_option("-o,--output", o->output, "Output directory")->capture_default_str();
  auto* radius = cmd->add_option("--radius", o->radius, "Particle radius [m]")->check(CLI::PositiveNumber);
  cmd->add_option("--count", o->count, "Particle count instead of a radius")->check(CLI::PositiveNumber)->excludes(radius);
  cmd->add_option("--density", o->density, "Density of the solid [kg/m^3]")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the generator that places the particles")->capture_default_str();
  cmd->add_option("--coverage", o->coverage,
                  "Target covering radius / r: 1 = the particle spheres cover the surface; up to (r + r_grain) / r "
                  "still stops grains of radius r_grain")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--grain-radius", o->grain_radius, "Grain radius [m] for the leak figure c / (r + r_grain)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--voxel", o->voxel, "SDF voxel [m] (default r / 2)")->check(CLI::PositiveNumber);
  cmd->add_option("--rounds", o->rounds, "Most hole-closing rounds")->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_option("--probes", o->probes, "Surface points the covering radius is measured on")->capture_default_str();
  cmd->add_option("--scale", o->scale, "Multiply coordinates by this factor first")->check(CLI::PositiveNumber);
  cmd->add_flag("--allow-open", o->allow_open, "Sample an open or non-manifold mesh anyway (its mass properties are then approximate)");
  cmd->add_flag("--json", o->json, "Print the body.json summary on stdout");
  cmd->add_flag("--timings", o->timings, "Per-kernel GPU times");
  return [o, &global] {
    TriangleMesh mesh = load_mesh(o->mesh);
    if (o->scale != 1.0) scale_mesh(mesh, o->scale);
    const MeshReport report = analyze_mesh(mesh);
    if (!report.watertight() && !o->allow_open) {
      throw InputError(o->mesh, "is not a closed, consistently oriented solid (" + closed_solid_problems(report) +
                                    "); `tetrasand info` shows the full report; --allow-open samples it anyway\n" +
                                    format_report(report));
    }
    sampler::SampleSettings settings;
    settings.radius = o->radius;
    settings.count = o->count;
    settings.coverage = o->coverage;
    settings.grain_radius = o->grain_radius;
    settings.voxel_size = o->voxel;
    settings.density = o->density;
    settings.seed = o->seed;
    settings.max_rounds = o->rounds;
    settings.probes = o->probes;
    settings.timings = o->timings;

    gpu::ContextOptions context_options;
    context_options.device = global.device;
    context_options.debug = global.gl_debug;
    gpu::Context context(context_options);
    const bool terminal = ::isatty(STDERR_FILENO) != 0;
    const auto progress = [&](const sampler::SampleProgress& p) {
      const std::string line = fmt::format("round {}  iteration {:>5}  particles {:>8}  residual {:.2e}", p.round,
                                           p.iteration, p.particles, p.residual);
      if (terminal) std::fprintf(stderr, "\r%s   ", line.c_str());
    };
    sampler::SampleResult result = sampler::sample_mesh(context, mesh, settings, progress);
    if (terminal) std::fprintf(stderr, "\n");
    for (const auto& warning : result.warnings) log::warn("{}", warning);

    sampler::ParticleBody& body = result.body;
    body.source_path = o->mesh;
    body.source_sha256 = sha256_file(o->mesh);
    const std::string name = std::filesystem::path(o->mesh).stem().string();
    const std::filesystem::path json = sampler::write_body(o->output, name, body);
    const auto& q = body.quality;
    if (o->json) {
      std::ifstream in(json);
      fmt::print("{}\n", nlohmann::json::parse(in).dump(2));
    } else {
      fmt::print("{} -> {}\n", o->mesh, json.string());
      fmt::print("  particles        {} of radius {:.6g} m (area estimate {}, {:+.1f} %)\n", body.positions.size(),
                 body.particle_radius, result.estimated_count,
                 100.0 * (static_cast<double>(body.positions.size()) / static_cast<double>(result.estimated_count) - 1.0));
      fmt::print("  evenness         relative radius {:.3f}, CV of nearest-neighbour distances {:.3f}\n",
                 q.relative_radius, q.cv);
      fmt::print("  coverage         covering radius {:.6g} m = {:.3f} r{}\n", q.covering_radius, q.covering_over_r,
                 q.covering_over_r_plus_grain ? fmt::format(" = {:.3f} (r + r_grain)", *q.covering_over_r_plus_grain) : "");
      fmt::print("  on the surface   largest |phi| = {:.2e} r\n", q.max_abs_phi_over_r);
      fmt::print("  work             {} iterations, {} hole-closing rounds, {}, {:.2f} s on {}\n", q.iterations,
                 q.injection_rounds, q.converged ? "converged" : "NOT converged", q.seconds, context.summary());
      fmt::print("  mass properties  {:.6g} kg, volume {:.6g} m^3, centre of mass ({:.6g}, {:.6g}, {:.6g}) m\n", body.mass,
                 body.volume, body.center_of_mass.x(), body.center_of_mass.y(), body.center_of_mass.z());
    }
    if (o->timings) fmt::print("{}", result.timing_report);
    return 0;
  };
}

}  // namespace ts::app
