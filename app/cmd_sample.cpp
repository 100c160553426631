// `tetrasand sample MESH...`: the main job. A closed mesh becomes a particle rigid body; many meshes (or list
// files) make a batch (app/sample_batch.h) with one GPU context (none when nothing runs on the GPU). This
// file holds the options and the conversion of one mesh; the report is app/sample_report.h.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "app/commands.h"
#include "app/numeric_options.h"
#include "app/progress.h"
#include "app/sample_batch.h"
#include "app/sample_report.h"
#include "body/body_file.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/mesh_io.h"
#include "gpu/backend.h"
#include "preview/body_preview.h"
#include "sampler/body_verdict.h"
#include "sampler/sample_mesh.h"
#include "sdf/scan_calibration.h"

namespace ts::app {

namespace {

struct Options {
  BatchInputs in;    // meshes, lists, --shard, --summary and the output directory
  std::string mesh;  // the one being converted
  bool batch = false;
  // The sampler's settings, bound to the options directly; sign and mass method follow the mesh.
  sampler::SampleSettings sampling;
  double scale = 1.0;
  std::size_t sdf_budget_mib = 1024;
  std::string sign = "pseudonormal";
  bool json = false, allow_open = false, preview = false;
  std::vector<double> up{0.0, 0.0, 1.0};  // --preview's world up
  bool strict = false;                    // a body short of OK exits 1 (it is still written)
  std::string backend = "auto", sdf_backend = "auto";
  std::string scan = "auto";     // sdf::parse_scan_method; compute or geometry once resolved
  std::string scan_reason;       // why that method (sdf::ScanChoice::reason), when the SDF is scanned
  double context_seconds = 0.0;  // s, the GPU context's creation (once for a batch)
};

// Options are registered in the order --help lists them.
void add_input_options(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.in.inputs,
                  "Closed, consistently oriented triangle meshes; @FILE reads a list (one path a line)");
  cmd->add_option("--list", o.in.list,
                  "File listing meshes to convert, one path a line (relative to the file)");
  cmd->add_option("--shard", o.in.shard,
                  "I/N: convert only meshes k with k mod N = I of the expanded list (0 <= I < N)");
  cmd->add_option("--summary", o.in.summary,
                  "Summary CSV of a batch (default DIR/summary.csv, DIR/summary-I-of-N.csv with --shard)");
  cmd->add_option("-o,--output", o.in.output, "Output directory")->capture_default_str();
}

// Size, density, placement and the accuracy of the arrangement.
void add_sampling_options(CLI::App* cmd, Options& o) {
  sampler::SampleSettings& s = o.sampling;
  auto* radius = cmd->add_option("--radius", s.radius, "Particle radius [m]")->check(positive());
  cmd->add_option("--count", s.count, "Particle count instead of a radius")
      ->check(positive())
      ->excludes(radius);
  cmd->add_option("--density", s.density, "Density of the solid [kg/m^3]")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--seed", s.seed, "Seed of the generator that places the particles")
      ->check(finite())
      ->capture_default_str();
  cmd->add_option("--coverage", s.coverage,
                  "Target covering radius / r: 1 = the particle spheres cover the surface; up to (r + "
                  "r_grain) / r still stops grains of radius r_grain")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--grain-radius", s.grain_radius, "Grain radius [m] for the leak figure c / (r + r_grain)")
      ->check(positive());
  cmd->add_option("--voxel", s.voxel_size, "SDF voxel [m] (default r / 2)")->check(positive());
  cmd->add_option("--rounds", s.max_rounds, "Most hole-closing rounds")
      ->check(non_negative())
      ->capture_default_str();
  cmd->add_option("--probes", s.probes,
                  "Most random surface points of the statistical covering radius (beside the certificate)")
      ->check(finite())
      ->capture_default_str();
  cmd->add_option("--probes-per-particle", s.probes_per_particle,
                  "Probes per surface particle (at least 65536, at most --probes); 0: always --probes")
      ->check(non_negative())
      ->capture_default_str();
  cmd->add_option("--certificate-floor", s.certificate.floor_divisor,
                  "The coverage certificate splits triangles no finer than r / this (its bound is within "
                  "max(r, c) / this of the covering radius c)")
      ->check(range(1.0, 4096.0))
      ->capture_default_str();
  cmd->add_option("--scale", o.scale, "Multiply coordinates by this factor first")->check(positive());
  cmd->add_option("--max-iterations", s.relax.max_iterations,
                  "Most relaxation steps of the first relaxation (later rounds: 200)")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--backend", o.backend,
                  "Where the relaxation, the coverage certificate and --preview run: gpu (compute kernels, the "
                  "GL renderer), cpu (the same algorithms on all cores, the CPU renderer; with --sdf-backend "
                  "auto or cpu no GL context at all) or auto (cpu on a software renderer, else gpu: the rule "
                  "of every command)")
      ->check(CLI::IsMember({"auto", "gpu", "cpu"}))
      ->capture_default_str();
  cmd->add_option("--sdf-backend", o.sdf_backend,
                  "Where the SDF is built: gpu (scan conversion), cpu (exact distance, all cores), openvdb "
                  "(the CPU by OpenVDB's meshToVolume, all cores: approximate, closed meshes) or auto (as "
                  "--backend auto: on a software renderer or without GL cpu, else gpu)")
      ->check(CLI::IsMember({"auto", "gpu", "cpu", "openvdb"}))
      ->capture_default_str();
  cmd->add_option(
         "--scan", o.scan,
         "How the GPU scan conversion reaches the voxels (SDF on the GPU): compute (compute shaders), "
         "geometry (geometry shader and rasteriser) or auto (compute, unless a calibration cached for "
         "this renderer and driver found geometry faster)")
      ->check(CLI::IsMember({"auto", "compute", "geometry"}))
      ->capture_default_str();
  cmd->add_option("--sdf-budget-mib", o.sdf_budget_mib,
                  "Most memory the sparse SDF may take [MiB] (GPU memory; host memory with the CPU "
                  "relaxation); a larger field stops the run (exit 1) with the particle count (or, with "
                  "--voxel, the voxel) that fits")
      ->check(positive())
      ->capture_default_str();
}

// Inside and outside, the interior, and what is printed or written besides the body.
void add_solid_and_output_options(CLI::App* cmd, Options& o) {
  cmd->add_option("--sign", o.sign,
                  "Inside/outside by pseudonormals (closed meshes only) or by the generalised winding number "
                  "(also open or non-manifold meshes: they are sampled with a warning, their mass properties "
                  "integrated over the winding-number solid)")
      ->check(CLI::IsMember({"pseudonormal", "winding"}))
      ->capture_default_str();
  cmd->add_flag("--allow-open", o.allow_open, "Same as --sign winding (the older name)");
  cmd->add_flag("--fill", o.sampling.fill,
                "Also fill the inside: particles on a face-centred cubic lattice of spacing 2r wherever phi "
                "<= -r (after the surface ones in the PLY, with normal 0 0 0)");
  cmd->add_flag("--json", o.json, "Print the body.json summary, the verdict and the thin features on stdout");
  cmd->add_flag(
      "--strict", o.strict,
      "Exit 1 unless the verdict is 'body OK' (the body is still written; a batch converts every mesh)");
  cmd->add_flag("--timings", o.sampling.timings, "Per-kernel GPU times and host-GPU round trips");
  cmd->add_flag("--preview", o.preview,
                "Also write NAME.preview.png: the mesh's SDF ray-cast with the particles over it (drawn where "
                "--backend says)");
  cmd->add_option("--up", o.up,
                  "With --preview: the mesh's up X,Y,Z (+z by convention; `info` tells its tallest axis)")
      ->delimiter(',')
      ->expected(3)
      ->check(finite())
      ->capture_default_str();
}

// The mesh, scaled, and the sign and mass methods it allows: an open or inconsistent mesh is refused unless
// --sign winding, which samples it from its winding-number solid.
TriangleMesh load_sample_mesh(const Options& o, sampler::SampleSettings& settings) {
  TriangleMesh mesh = load_mesh(o.mesh);
  if (o.scale != 1.0) scale_mesh(mesh, o.scale);
  sampler::check_sample_mesh(mesh, o.mesh, o.sign == "winding" || o.allow_open, settings);
  return mesh;
}

sampler::SampleResult sample_with_progress(gpu::Context* context, const TriangleMesh& mesh,
                                           const sampler::SampleSettings& settings) {
  Progress progress;
  const auto report = [&](const sampler::SampleProgress& p) {
    progress.update(fmt::format("round {}  iteration {:>5}  particles {:>8}  residual {:.2e}", p.round,
                                p.iteration, p.particles, p.residual));
  };
  sampler::SampleResult result = sampler::sample_mesh(context, mesh, settings, report);
  progress.end();
  for (const auto& warning : result.warnings) log::warn("{}", warning);
  return result;
}

// The sampler's settings of this run: the options' figures and the backends they name (--sdf-backend openvdb:
// the CPU by OpenVDB's method).
sampler::SampleSettings settings_of(const Options& o) {
  sampler::SampleSettings settings = o.sampling;
  settings.max_sdf_bytes = o.sdf_budget_mib << 20;
  settings.backend = gpu::parse_backend(o.backend).value();  // CLI::IsMember checked the spelling
  const bool openvdb = o.sdf_backend == "openvdb";
  settings.sdf_backend = openvdb ? gpu::Backend::Cpu : gpu::parse_backend(o.sdf_backend).value();
  settings.cpu_sdf = openvdb ? sampler::CpuSdfMethod::OpenVdb : sampler::CpuSdfMethod::Exact;
  settings.scan = sdf::parse_scan_method(o.scan).value();  // CLI::IsMember checked the spelling
  return settings;
}

struct PreviewDone {
  std::filesystem::path png;
  preview::BodyPreviewReport report;
  bool on_gpu = false;
};

// NAME.preview.png, signed as the body was sampled (`sign`): an open mesh sampled by winding number
// previews as its particles over its winding-number surface, not as the box pseudonormal signs flood.
PreviewDone write_preview(const Options& o, gpu::Context* context, const TriangleMesh& mesh,
                          const body::ParticleBody& body, const std::string& name, sdf::SignMethod sign) {
  PreviewDone done;
  done.png = std::filesystem::path(o.in.output) / (name + ".preview.png");
  preview::BodyPreviewSettings look;
  look.up = Eigen::Vector3d(o.up[0], o.up[1], o.up[2]);
  look.sign = sign;
  // The preview is drawn where --backend runs the relaxation (gpu/backend.h): on the CPU without a device
  // or on a software renderer.
  done.on_gpu = gpu::resolve_backend(settings_of(o).backend, context) == gpu::Backend::Gpu;
  done.report = preview::write_body_preview(done.on_gpu ? context : nullptr, mesh, body, done.png, {o.mesh}, look);
  if (!done.report.field_drawn) {
    log::warn("{}: the preview's SDF reads inside at the corner of its box (signs unreliable): drawn without it, "
              "the particles alone", o.mesh);
  }
  return done;
}

// The preview's line of the report (a log line under --json: standard output stays the JSON).
void report_preview(const Options& o, const PreviewDone& done) {
  const std::string line = fmt::format("{}, {:.2f} s on the {}{}", done.png.string(), done.report.seconds,
                                       done.on_gpu ? "GPU, " + done.report.gpu_path : "CPU",
                                       done.report.field_drawn ? "" : " (particles only: the SDF's signs are unreliable)");
  if (o.json) {
    log::info("preview: {}", line);
  } else {
    fmt::print("  preview          {}\n", line);
  }
}

// One mesh: sample, write the body (and its preview), report and judge it; `row` gets the batch summary's
// figures. Returns the mesh's exit code: 1 under --strict when the verdict is short of OK.
int convert_one(const Options& o, gpu::Context* context, BatchRow& row) {
  const auto start = std::chrono::steady_clock::now();
  const auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  CommandSeconds seconds;
  seconds.context = o.context_seconds;
  sampler::SampleSettings settings = settings_of(o);
  const TriangleMesh mesh = load_sample_mesh(o, settings);
  seconds.load = since(start);
  sampler::SampleResult result =
      naming_file(o.mesh, [&] { return sample_with_progress(context, mesh, settings); });
  const auto write_start = std::chrono::steady_clock::now();
  body::ParticleBody& body = result.body;
  body.source_path = o.mesh;
  body.source_sha256 = sha256_file(o.mesh);
  const std::string name = std::filesystem::path(o.mesh).stem().string();
  const std::filesystem::path json = body::write_body(o.in.output, name, body);
  seconds.write = since(write_start);
  std::optional<PreviewDone> previewed;
  if (o.preview) previewed = write_preview(o, context, mesh, body, name, settings.sign);
  if (previewed) seconds.preview = previewed->report.seconds;
  seconds.total = since(start) + seconds.context;
  row.status = "ok", row.body_json = json.string(), row.particles = body.positions.size();
  row.quality = body.quality, row.radius = body.particle_radius;
  const sampler::BodyVerdict verdict = sampler::judge_body(body, result.thin);
  row.verdict = sampler::verdict_name(verdict.verdict), row.verdict_reasons = verdict.reasons;
  if (o.json) {
    print_json(json, verdict, result.thin, run_json(result, seconds, context), o.batch);
  } else {
    const gpu::Backend requested = settings.backend;
    const std::string reason =
        gpu::backend_reason(requested, gpu::resolve_backend(requested, context), gpu::describe(context));
    const std::string scan = o.scan_reason.empty() ? "" : fmt::format("scan {} ({})", o.scan, o.scan_reason);
    print_body_report({o.mesh, o.sampling.fill, reason, scan}, result, json, context);
  }
  if (previewed) report_preview(o, *previewed);
  if (o.sampling.timings) print_timings(result, seconds);
  if (!o.json) fmt::print("verdict: {}: {}\n", row.verdict, fmt::join(verdict.reasons, "; "));
  return o.strict && verdict.verdict != sampler::Verdict::Ok ? 1 : 0;
}

// Whether a run needs a GL context at all: auto asks the device what it is, the GPU paths use it.
// `--backend cpu` without --sdf-backend gpu runs everything on the CPU, the SDF and --preview included
// (--sdf-backend auto then means a CPU field, exact or OpenVDB's), so it works where EGL does not.
bool needs_gl_context(const Options& o) { return o.backend != "cpu" || o.sdf_backend == "gpu"; }

// --scan auto, once for the whole batch, where the SDF is scanned on the GPU: the cached calibration of
// this renderer and driver, or a calibration now (sdf/scan_calibration.h).
void resolve_scan(Options& o, gpu::Context* context) {
  const sampler::SampleSettings settings = settings_of(o);
  if (context == nullptr || settings.cpu_sdf == sampler::CpuSdfMethod::OpenVdb ||
      gpu::resolve_backend(settings.sdf_backend, context) != gpu::Backend::Gpu)
    return;
  const sdf::ScanChoice scan = sdf::choose_scan(*context, o.scan);
  o.scan = sdf::scan_method_name(scan.method);
  o.scan_reason = scan.reason;
}

// The run's backend line (gpu/backend.h), once for the whole batch: where the relaxation and the certificate
// run and why, and where the SDF is built. On standard output beside the report; with --json a log line, so
// standard output stays the JSON.
void print_backend_line(const Options& o, const gpu::Context* context) {
  const sampler::SampleSettings settings = settings_of(o);
  const gpu::Backend relax = gpu::resolve_backend(settings.backend, context);
  const gpu::Backend sdf = gpu::resolve_backend(settings.sdf_backend, context);
  const std::string field =
      settings.cpu_sdf == sampler::CpuSdfMethod::OpenVdb ? "by OpenVDB's meshToVolume on the CPU"
      : sdf == gpu::Backend::Gpu ? fmt::format("by GPU scan {} ({})", sdf::scan_method_name(settings.scan),
                                               o.scan_reason)
                                 : "by exact distance on the CPU";
  const std::string note = fmt::format("SDF: {}, {}", field, o.sdf_backend == "auto" ? "auto" : "asked for");
  const std::string line = gpu::backend_line(settings.backend, relax, gpu::describe(context), true,
                                             o.preview ? "relaxation, certificate and preview" : "relaxation and certificate",
                                             note);
  if (o.json) {
    log::info("{}", line);
  } else {
    fmt::print("{}\n", line);
  }
}

int run_sample(Options& o, const GlobalOptions& global) {
  if (o.in.inputs.empty() && o.in.list.empty())
    throw Error(ExitCode::Usage, "sample: give at least one MESH or --list FILE");
  if (!(Eigen::Vector3d(o.up[0], o.up[1], o.up[2]).norm() > 0.0))
    throw Error(ExitCode::Usage, "sample: --up must not be the zero vector");
  const std::vector<std::string> meshes = expand_inputs(o.in);
  o.batch = is_batch(o.in, meshes.size());
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<gpu::Context> context;  // one context for the whole batch, if any stage needs one
  if (needs_gl_context(o)) context = std::make_unique<gpu::Context>(context_options(global));
  o.context_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  resolve_scan(o, context.get());
  print_backend_line(o, context.get());
  if (o.batch) {
    return run_batch(meshes, o.in, o.json, o.strict, [&](const std::string& mesh, bool first, BatchRow& row) {
      Options one = o;
      one.mesh = mesh;
      if (!first) one.context_seconds = 0.0;  // the batch's one context counts with its first mesh
      return convert_one(one, context.get(), row);
    });
  }
  o.mesh = meshes.front();
  BatchRow row;
  return convert_one(o, context.get(), row);
}

}  // namespace

Runner add_sample_command(CLI::App& app, const GlobalOptions& global) {
  return add_command<Options>(
      app, global, "sample",
      "Convert a closed mesh into a particle rigid body (NAME.particles.ply + NAME.body.json)", run_sample,
      add_input_options, add_sampling_options, add_solid_and_output_options);
}

}  // namespace ts::app
