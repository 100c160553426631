// `tetrasand sample MESH...`: the main job. A closed mesh becomes a particle rigid body; many meshes
// (or list files) make a batch with one GPU context (none when nothing runs on the GPU), a summary CSV
// and --shard I/N.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <vector>

#include "app/commands.h"
#include "app/numeric_options.h"
#include "body/body_file.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/mesh_io.h"
#include "core/mesh_report.h"
#include "preview/body_preview.h"
#include "sampler/body_verdict.h"
#include "sampler/sample_mesh.h"

namespace ts::app {

namespace {

// Batch conversion (a whole asset library, split across machines with no coordination): mesh k of the
// expanded input list belongs to shard k mod N, so `--shard I/N` for I = 0..N-1 converts every mesh
// exactly once; a failed mesh is a row of the summary CSV, not the end of the batch.
struct Options {
  std::string mesh, output = ".";  // mesh: the one being converted
  std::vector<std::string> inputs;  // meshes and @list files from the command line
  std::string list, shard, summary;
  bool batch = false;
  // The sampler's settings, bound to the options directly; sign and mass method follow the mesh.
  sampler::SampleSettings sampling;
  double scale = 1.0;
  std::size_t sdf_budget_mib = 1024;
  std::string sign = "pseudonormal";
  bool json = false, allow_open = false, preview = false;
  std::vector<double> up{0.0, 0.0, 1.0};  // --preview's world up
  bool strict = false;                     // a body short of OK exits 1 (it is still written)
  std::string backend = "auto", sdf_backend = "auto";
  double context_seconds = 0.0;  // s, the GPU context's creation (once for a batch)
};

// Wall time of the command's own stages of one mesh [s]; sample_mesh's are in SampleResult::stages.
struct CommandSeconds {
  double context = 0.0, load = 0.0, write = 0.0, total = 0.0;
};

struct BatchRow {
  std::string mesh, status = "ok", error, body_json;
  std::string verdict;  // verdict_name(); empty for a failed mesh
  std::vector<std::string> verdict_reasons;
  int exit_code = 0;
  std::size_t particles = 0;
  body::ParticleBody::Quality quality;
  double radius = 0.0;
};

// Lines of a list file: one mesh path each, relative to the list's folder unless absolute; blank
// lines and lines starting with # are skipped.
void append_list(const std::filesystem::path& list, std::vector<std::string>& out) {
  std::istringstream in(read_file(list));
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    const std::filesystem::path path = line.substr(first, last - first + 1);
    out.push_back((path.is_absolute() ? path : list.parent_path() / path).lexically_normal().string());
  }
}

struct Shard {
  std::size_t index = 0, count = 1;
};

Shard parse_shard(const std::string& text) {
  Shard s;
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    std::size_t used = 0;
    s.index = std::stoul(text.substr(0, slash), &used);
    if (used != slash) throw std::invalid_argument("index");
    s.count = std::stoul(text.substr(slash + 1), &used);
    if (used != text.size() - slash - 1) throw std::invalid_argument("count");
  } catch (const std::exception&) {
    throw Error(ExitCode::Usage, "--shard wants I/N with 0 <= I < N (got '" + text + "')");
  }
  if (s.count == 0 || s.index >= s.count) throw Error(ExitCode::Usage, "--shard wants I/N with 0 <= I < N (got '" + text + "')");
  return s;
}

std::vector<std::string> expand_inputs(const Options& o) {
  std::vector<std::string> all;
  for (const std::string& item : o.inputs) {
    if (item.size() > 1 && item[0] == '@') {
      append_list(item.substr(1), all);
    } else {
      all.push_back(item);
    }
  }
  if (!o.list.empty()) append_list(o.list, all);
  if (all.empty()) throw InputError("no meshes to convert (empty list)");
  const Shard shard = parse_shard(o.shard.empty() ? "0/1" : o.shard);
  std::vector<std::string> mine;
  for (std::size_t k = 0; k < all.size(); ++k)
    if (k % shard.count == shard.index) mine.push_back(all[k]);
  return mine;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return quoted + "\"";
}

void write_summary(const std::filesystem::path& path, const std::vector<BatchRow>& rows) {
  std::string csv =
      "mesh,status,exit_code,particles,particle_radius_m,relative_radius,cv,covering_over_r,"
      "coverage_certified,covering_bound_over_r,uncovered_subtriangles,max_abs_phi_over_r,iterations,"
      "injection_rounds,converged,seconds,verdict,verdict_reasons,body_json,error\n";
  for (const BatchRow& r : rows) {
    const auto& q = r.quality;
    // A failed mesh has no certificate: its certificate columns are empty.
    const auto& c = q.certificate;
    csv += fmt::format(
        "{},{},{},{},{:.9g},{:.6f},{:.6f},{:.6f},{},{},{},{:.3e},{},{},{},{:.3f},{},{},{},{}\n",
        csv_field(r.mesh), r.status, r.exit_code, r.particles, r.radius, q.relative_radius, q.cv,
        q.covering_over_r, c ? (c->certified ? "1" : "0") : "",
        c ? fmt::format("{:.6f}", c->bound_over_r) : "", c ? std::to_string(c->uncovered_subtriangles) : "",
        q.max_abs_phi_over_r, q.iterations, q.injection_rounds, q.converged ? 1 : 0, q.seconds,
        csv_field(r.verdict), csv_field(fmt::format("{}", fmt::join(r.verdict_reasons, "; "))),
        csv_field(r.body_json), csv_field(r.error));
  }
  std::filesystem::create_directories(path.parent_path().empty() ? "." : path.parent_path());
  write_file_atomically(path, csv);
}

std::filesystem::path summary_path(const Options& o) {
  if (!o.summary.empty()) return o.summary;
  if (o.shard.empty()) return std::filesystem::path(o.output) / "summary.csv";
  const Shard s = parse_shard(o.shard);
  return std::filesystem::path(o.output) / fmt::format("summary-{}-of-{}.csv", s.index, s.count);
}

// Options are registered in the order --help lists them.
void add_input_options(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.inputs, "Closed, consistently oriented triangle meshes; @FILE reads a list (one path a line)");
  cmd->add_option("--list", o.list, "File listing meshes to convert, one path a line (relative to the file)");
  cmd->add_option("--shard", o.shard, "I/N: convert only meshes k with k mod N = I of the expanded list (0 <= I < N)");
  cmd->add_option("--summary", o.summary, "Summary CSV of a batch (default DIR/summary.csv, DIR/summary-I-of-N.csv with --shard)");
  cmd->add_option("-o,--output", o.output, "Output directory")->capture_default_str();
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
  cmd->add_option(
         "--coverage", s.coverage,
         "Target covering radius / r: 1 = the particle spheres cover the surface; up to (r + r_grain) / r "
         "still stops grains of radius r_grain")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--grain-radius", s.grain_radius, "Grain radius [m] for the leak figure c / (r + r_grain)")
      ->check(positive());
  cmd->add_option("--voxel", s.voxel_size, "SDF voxel [m] (default r / 2)")->check(positive());
  cmd->add_option("--rounds", s.max_rounds, "Most hole-closing rounds")->check(non_negative())->capture_default_str();
  cmd->add_option("--probes", s.probes,
                  "Most random surface points of the statistical covering radius (beside the certificate)")
      ->check(finite())
      ->capture_default_str();
  cmd->add_option("--probes-per-particle", s.probes_per_particle,
                  "Probes per surface particle (at least 65536, at most --probes); 0: always --probes")
      ->check(non_negative())
      ->capture_default_str();
  cmd->add_option(
         "--certificate-floor", s.certificate.floor_divisor,
         "The coverage certificate splits triangles no finer than r / this (its bound is within max(r, c) / "
         "this of the covering radius c)")
      ->check(range(1.0, 4096.0))
      ->capture_default_str();
  cmd->add_option("--scale", o.scale, "Multiply coordinates by this factor first")->check(positive());
  cmd->add_option("--max-iterations", s.relax.max_iterations, "Most relaxation steps of the first relaxation (later rounds: 200)")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option(
         "--backend", o.backend,
         "Where the relaxation and the coverage certificate run: gpu (compute kernels), cpu (the same "
         "algorithms on all cores; with --sdf-backend auto or cpu and no --preview, no GL context at all) "
         "or auto (cpu on a software renderer, else gpu)")
      ->check(CLI::IsMember({"auto", "gpu", "cpu"}))
      ->capture_default_str();
  cmd->add_option(
         "--sdf-backend", o.sdf_backend,
         "Where the SDF is built: gpu (scan conversion), cpu (exact distance, all cores), openvdb "
         "(OpenVDB's meshToVolume, all cores: approximate, closed meshes) or auto (on a software renderer "
         "or without GL: cpu; else gpu)")
      ->check(CLI::IsMember({"auto", "gpu", "cpu", "openvdb"}))
      ->capture_default_str();
  cmd->add_option(
         "--sdf-budget-mib", o.sdf_budget_mib,
         "Most memory the sparse SDF may take [MiB] (GPU memory; host memory with the CPU relaxation); a "
         "larger field stops the run (exit 1) with the particle count (or, with --voxel, the voxel) that "
         "fits")
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
                "Also fill the inside: particles on a face-centred cubic lattice of spacing 2r wherever phi <= -r "
                "(after the surface ones in the PLY, with normal 0 0 0)");
  cmd->add_flag("--json", o.json, "Print the body.json summary, the verdict and the thin features on stdout");
  cmd->add_flag(
      "--strict", o.strict,
      "Exit 1 unless the verdict is 'body OK' (the body is still written; a batch converts every mesh)");
  cmd->add_flag("--timings", o.sampling.timings, "Per-kernel GPU times and host-GPU round trips");
  cmd->add_flag("--preview", o.preview, "Also write NAME.preview.png: the mesh's SDF ray-cast with the particles over it");
  cmd->add_option("--up", o.up,
                  "With --preview: the mesh's up X,Y,Z (+z by convention; `info` tells its tallest axis)")
      ->delimiter(',')
      ->expected(3)
      ->check(finite())
      ->capture_default_str();
}

// The mesh, scaled, and the sign and mass methods it allows: an open or inconsistent mesh is refused
// unless --sign winding, which samples it from its winding-number solid.
TriangleMesh load_sample_mesh(const Options& o, sampler::SampleSettings& settings) {
  TriangleMesh mesh = load_mesh(o.mesh);
  if (o.scale != 1.0) scale_mesh(mesh, o.scale);
  const MeshReport report = analyze_mesh(mesh);
  const bool winding = o.sign == "winding" || o.allow_open;
  settings.sign = winding ? sdf::SignMethod::Winding : sdf::SignMethod::Pseudonormal;
  if (report.watertight()) return mesh;
  if (!winding) {
    throw InputError(o.mesh, "is not a closed, consistently oriented solid (" + closed_solid_problems(report) +
                                 "); `tetrasand info` shows the full report; --sign winding samples it anyway\n" +
                                 format_report(report));
  }
  log::warn("{}: not a closed solid ({}): sampled with winding-number signs; the particles cover the mesh's own "
            "surface only (holes stay open), mass properties come from the winding-number solid",
            o.mesh, closed_solid_problems(report));
  settings.mass_method = body::MassMethod::WindingCells;
  return mesh;
}

sampler::SampleResult sample_with_progress(gpu::Context* context, const TriangleMesh& mesh,
                                           const sampler::SampleSettings& settings) {
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  const auto progress = [&](const sampler::SampleProgress& p) {
    const std::string line = fmt::format("round {}  iteration {:>5}  particles {:>8}  residual {:.2e}", p.round,
                                         p.iteration, p.particles, p.residual);
    if (terminal) std::fprintf(stderr, "\r%s   ", line.c_str());
  };
  sampler::SampleResult result = sampler::sample_mesh(context, mesh, settings, progress);
  if (terminal) std::fprintf(stderr, "\n");
  for (const auto& warning : result.warnings) log::warn("{}", warning);
  return result;
}

// The certificate: proven or not, its bound and lower figure, and where the deepest holes are.
void print_certificate_line(const sampler::SampleResult& result) {
  const sampler::CoverageCertificate& c = result.certificate;
  const double r = result.body.particle_radius;
  if (c.covered) {
    fmt::print(
        "  certificate      certified: every surface point lies within r of a particle centre; "
        "covering radius <= {:.3f} r (>= {:.3f} r), {} sub-triangles down to r / {:.0f}\n",
        c.covering_bound / r, c.covering_lower / r, c.evaluated, r / c.floor);
    return;
  }
  fmt::print(
      "  certificate      NOT certified: covering radius <= {:.3f} r (>= {:.3f} r); {} sub-triangles "
      "({:.3g} m^2) not proven within r of a particle, in {}{} holes\n",
      c.covering_bound / r, c.covering_lower / r, c.uncovered, c.uncovered_area,
      result.holes.size() == sampler::kReportedHoles ? "at least " : "", result.holes.size());
  for (std::size_t k = 0; k < std::min<std::size_t>(result.holes.size(), 5); ++k) {
    const auto& h = result.holes[k];
    fmt::print("                   hole {:.3f} r deep at ({:.6g}, {:.6g}, {:.6g}) m\n", h.depth / r,
               h.position.x(), h.position.y(), h.position.z());
  }
}

// Thin regions the report and --json list (largest area first); the rest are counted.
constexpr std::size_t kListedThinRegions = 5;

std::string box_text(const Aabb& b) {
  return fmt::format("[{:.4g}, {:.4g}, {:.4g}] .. [{:.4g}, {:.4g}, {:.4g}] m", b.min.x(), b.min.y(),
                     b.min.z(), b.max.x(), b.max.y(), b.max.z());
}

// Where the solid is thinner than the spacing, region by region, and the radius that resolves each.
void print_thin_features(const sampler::ThinFeatures& thin, double r) {
  if (thin.triangles == 0) return;
  fmt::print(
      "  thin features    {} triangles ({:.2f} % of the area) in {} region{} thinner than {:.4g} m ({:.3f} "
      "r):\n",
      thin.triangles, 100.0 * thin.area_share, thin.regions.size(), thin.regions.size() == 1 ? "" : "s",
      thin.threshold, thin.threshold / r);
  const std::size_t listed = std::min(thin.regions.size(), kListedThinRegions);
  double rest = 0.0;
  for (std::size_t k = 0; k < thin.regions.size(); ++k) {
    const sampler::ThinRegion& g = thin.regions[k];
    if (k >= listed) {
      rest += g.area_share;
      continue;
    }
    fmt::print(
        "                   {:.2f} % of the area, {} triangle{}, {}, {:.3g} m thick at the thinnest: {}\n",
        100.0 * g.area_share, g.triangles, g.triangles == 1 ? "" : "s", box_text(g.box), g.thinnest,
        sampler::resolving_radii_text(g));
  }
  if (listed < thin.regions.size()) {
    fmt::print("                   and {} more regions ({:.2f} % of the area)\n",
               thin.regions.size() - listed, 100.0 * rest);
  }
  fmt::print("                   {}\n", sampler::local_radius_advice());
}

nlohmann::json thin_features_json(const sampler::ThinFeatures& thin) {
  nlohmann::json regions = nlohmann::json::array();
  for (std::size_t k = 0; k < std::min(thin.regions.size(), kListedThinRegions); ++k) {
    const sampler::ThinRegion& g = thin.regions[k];
    regions.push_back({{"box_min", {g.box.min.x(), g.box.min.y(), g.box.min.z()}},
                       {"box_max", {g.box.max.x(), g.box.max.y(), g.box.max.z()}},
                       {"triangles", g.triangles},
                       {"area_share", g.area_share},
                       {"thinnest", g.thinnest},
                       {"resolving_radius", g.resolving_radius},
                       {"mostly_resolving_radius", g.mostly_resolving_radius}});
  }
  return {{"threshold", thin.threshold},
          {"triangles", thin.triangles},
          {"area_share", thin.area_share},
          {"region_count", thin.regions.size()},
          {"regions", regions},
          {"regions_not_listed", thin.regions.size() - regions.size()}};
}

// How the SDF's path reads in the stage table and in the report's device line.
struct SdfPathWords {
  const char* stage;
  const char* device;
};
SdfPathWords sdf_path_words(sampler::SdfPath path) {
  switch (path) {
    case sampler::SdfPath::Exact:
      return {"exact distance (CPU)", "by exact distance on the CPU"};
    case sampler::SdfPath::OpenVdb:
      return {"OpenVDB meshToVolume (CPU)", "by OpenVDB's meshToVolume on the CPU"};
    case sampler::SdfPath::Scan:
      break;
  }
  return {"scan conversion", "by GPU scan conversion"};
}

// The GL device, or what ran without one.
std::string device_name(const gpu::Context* context) {
  return context ? context->summary() : std::string("the CPU (no GL context)");
}

// Where the relaxation and the certificate ran, and why: "relaxation on the CPU, certificate on the
// GPU (auto: the GL device is a software renderer; --backend gpu forces the GPU)".
std::string backend_text(const sampler::SampleResult& result, const Options& o) {
  const auto device = [](bool cpu) { return cpu ? "CPU" : "GPU"; };
  std::string text = result.relax_on_cpu == result.certificate_on_cpu
                         ? fmt::format("relaxation and certificate on the {}", device(result.relax_on_cpu))
                         : fmt::format("relaxation on the {}, certificate on the {}",
                                       device(result.relax_on_cpu), device(result.certificate_on_cpu));
  if (o.backend != "auto") return text + fmt::format(" (--backend {})", o.backend);
  return text + (result.relax_on_cpu
                     ? " (auto: the GL device is a software renderer; --backend gpu forces the GPU)"
                     : " (auto: a hardware GL device)");
}

// The written body.json, and beside it what only this run knows: the verdict and the thin features.
// What this run cost and where it ran: the device, the SDF's path, the probes and each stage's seconds.
nlohmann::json run_json(const sampler::SampleResult& result, const CommandSeconds& c,
                        const gpu::Context* context) {
  const sampler::StageSeconds& t = result.stages;
  return {{"device", device_name(context)},
          {"software_device", context ? nlohmann::json(context->software()) : nlohmann::json(nullptr)},
          {"sdf_backend", sampler::sdf_path_name(result.sdf_path)},
          {"relax_backend", result.relax_on_cpu ? "cpu" : "gpu"},
          {"certificate_backend", result.certificate_on_cpu ? "cpu" : "gpu"},
          {"probes", result.probes},
          {"certificate_passes", result.certificate_passes},
          {"seconds",
           {{"context", c.context},
            {"load", c.load},
            {"plan", t.plan},
            {"sdf", t.sdf},
            {"setup", t.setup},
            {"relaxation", t.relaxation},
            {"projection", t.projection},
            {"certificate", t.certificate},
            {"injection", t.injection},
            {"probes", t.probes},
            {"thin_features", t.thin_features},
            {"body", t.body},
            {"write", c.write},
            {"total", c.total}}}};
}

// The stages of one mesh's run in the order they run, with their share of the command's time.
void print_stage_table(const sampler::SampleResult& result, const CommandSeconds& c) {
  const sampler::StageSeconds& t = result.stages;
  const std::vector<std::pair<std::string, double>> rows{
      {"GPU context creation", c.context},
      {"mesh load and checks", c.load},
      {"plan: exact-distance tree, sizing, mass", t.plan},
      {fmt::format("SDF: {}, NanoVDB{}", sdf_path_words(result.sdf_path).stage,
                   result.relax_on_cpu ? "" : ", upload"),
       t.sdf},
      {"seeds, programs and buffers", t.setup},
      {"relaxation (all rounds)", t.relaxation},
      {"projection and thinning", t.projection},
      {fmt::format("certificate ({} passes)", result.certificate_passes), t.certificate},
      {"hole injection", t.injection},
      {fmt::format("probe pass ({} probes)", result.probes), t.probes},
      {"thin features", t.thin_features},
      {"quality, holes, mass properties", t.body},
      {"writing the body", c.write}};
  fmt::print("{:<46} {:>9} {:>7}\n", "stage", "s", "share");
  for (const auto& [name, seconds] : rows) {
    fmt::print("{:<46} {:>9.3f} {:>6.1f}%\n", name, seconds, c.total > 0.0 ? 100.0 * seconds / c.total : 0.0);
  }
  fmt::print("{:<46} {:>9.3f}\n", "total (the command, this mesh)", c.total);
}

void print_json(const std::filesystem::path& json, const sampler::BodyVerdict& verdict,
                const sampler::ThinFeatures& thin, const nlohmann::json& run, bool one_line) {
  std::ifstream in(json);
  nlohmann::json out = nlohmann::json::parse(in);
  out["verdict"] = sampler::verdict_name(verdict.verdict);
  out["verdict_reasons"] = verdict.reasons;
  out["thin_features"] = thin_features_json(thin);
  out["run"] = run;
  fmt::print("{}\n", out.dump(one_line ? -1 : 2));  // a batch prints JSON Lines
}

void print_body_report(const Options& o, const sampler::SampleResult& result,
                       const std::filesystem::path& json, const gpu::Context* context) {
  const body::ParticleBody& body = result.body;
  const auto& q = body.quality;
  fmt::print("{} -> {}\n", o.mesh, json.string());
  const std::size_t surface = body.positions.size() - body.interior_count;
  fmt::print("  particles        {} of radius {:.6g} m on the surface (area estimate {}, {:+.1f} %)\n", surface,
             body.particle_radius, result.estimated_count,
             100.0 * (static_cast<double>(surface) / static_cast<double>(result.estimated_count) - 1.0));
  if (o.sampling.fill) {
    fmt::print("  interior         {} on an FCC lattice of spacing 2r (estimate from V - A r: {:.0f}); {} in all\n",
               body.interior_count, result.estimated_interior, body.positions.size());
  }
  fmt::print("  evenness         relative radius {:.3f}, CV of nearest-neighbour distances {:.3f}\n",
             q.relative_radius, q.cv);
  print_certificate_line(result);
  fmt::print(
      "  probes           covering radius {:.6g} m = {:.3f} r over {} random surface points (a lower "
      "figure){}\n",
      q.covering_radius, q.covering_over_r, result.probes,
      q.covering_over_r_plus_grain ? fmt::format(" = {:.3f} (r + r_grain)", *q.covering_over_r_plus_grain)
                                   : "");
  fmt::print("  on the surface   largest |phi| = {:.2e} r\n", q.max_abs_phi_over_r);
  print_thin_features(result.thin, body.particle_radius);
  const sampler::StageSeconds& t = result.stages;
  fmt::print("  device           {}: SDF {} {:.2f} s, relaxation {:.2f} s, certificate {:.2f} s; {}\n",
             device_name(context),
             sdf_path_words(result.sdf_path).device, t.sdf,
             t.relaxation, t.certificate, backend_text(result, o));
  fmt::print(
      "  work             {} iterations, {} hole-closing rounds, {}, {:.2f} s on {} (certificate {:.2f} s "
      "in {} passes, probes {:.2f} s)\n",
      q.iterations, q.injection_rounds, q.converged ? "converged" : "NOT converged", q.seconds,
      device_name(context), result.certificate_seconds, result.certificate_passes, result.probe_seconds);
  fmt::print("  mass properties  {:.6g} kg, volume {:.6g} m^3, centre of mass ({:.6g}, {:.6g}, {:.6g}) m, {}\n", body.mass,
             body.volume, body.center_of_mass.x(), body.center_of_mass.y(), body.center_of_mass.z(),
             body.mass_method == body::MassMethod::WindingCells
                 ? fmt::format("from the winding-number solid (cells of {:.3g} m)", body.mass_cell)
                 : std::string("from the closed mesh"));
}

// One mesh: sample, write the body (and its preview), report and judge it; `row` gets the batch
// summary's figures. Returns the mesh's exit code: 1 under --strict when the verdict is short of OK.
int convert_one(const Options& o, gpu::Context* context, BatchRow& row) {
  const auto start = std::chrono::steady_clock::now();
  const auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  CommandSeconds seconds;
  seconds.context = o.context_seconds;
  sampler::SampleSettings settings = o.sampling;
  settings.max_sdf_bytes = o.sdf_budget_mib << 20;
  settings.sdf_backend = o.sdf_backend == "cpu"       ? sampler::SdfBackend::Cpu
                         : o.sdf_backend == "gpu"     ? sampler::SdfBackend::Gpu
                         : o.sdf_backend == "openvdb" ? sampler::SdfBackend::OpenVdb
                                                      : sampler::SdfBackend::Auto;
  settings.backend = o.backend == "cpu"   ? sampler::SampleBackend::Cpu
                     : o.backend == "gpu" ? sampler::SampleBackend::Gpu
                                          : sampler::SampleBackend::Auto;
  const TriangleMesh mesh = load_sample_mesh(o, settings);
  seconds.load = since(start);
  sampler::SampleResult result =
      naming_file(o.mesh, [&] { return sample_with_progress(context, mesh, settings); });
  const auto write_start = std::chrono::steady_clock::now();
  body::ParticleBody& body = result.body;
  body.source_path = o.mesh;
  body.source_sha256 = sha256_file(o.mesh);
  const std::string name = std::filesystem::path(o.mesh).stem().string();
  const std::filesystem::path json = body::write_body(o.output, name, body);
  seconds.write = since(write_start);
  seconds.total = since(start) + seconds.context;
  row.status = "ok", row.body_json = json.string(), row.particles = body.positions.size();
  row.quality = body.quality, row.radius = body.particle_radius;
  const sampler::BodyVerdict verdict = sampler::judge_body(body, result.thin);
  row.verdict = sampler::verdict_name(verdict.verdict), row.verdict_reasons = verdict.reasons;
  if (o.json) {
    print_json(json, verdict, result.thin, run_json(result, seconds, context), o.batch);
  } else {
    print_body_report(o, result, json, context);
  }
  if (o.sampling.timings) {
    const sampler::FieldStats& f = result.field;
    const double per_voxel = f.band_voxels ? 1.0 / static_cast<double>(f.band_voxels) : 0.0;
    fmt::print("sparse SDF: {} band voxels; GPU {:.1f} MiB ({:.1f} bytes a band voxel), host {:.1f} MiB ({:.1f} bytes a "
               "band voxel) at its peak, scan conversion {:.1f} MiB on the GPU and {:.1f} MiB read back\n",
               f.band_voxels, f.gpu_bytes / 1048576.0, static_cast<double>(f.gpu_bytes) * per_voxel,
               f.host_bytes / 1048576.0, static_cast<double>(f.host_bytes) * per_voxel,
               f.scan_peak_gpu_bytes / 1048576.0, f.readback_bytes / 1048576.0);
    fmt::print("{}", result.timing_report);
    print_stage_table(result, seconds);
  }
  if (o.preview) {
    const std::filesystem::path png = std::filesystem::path(o.output) / (name + ".preview.png");
    preview::BodyPreviewSettings look;
    look.up = Eigen::Vector3d(o.up[0], o.up[1], o.up[2]);
    preview::write_body_preview(*context, mesh, body, png, {o.mesh}, look);  // needs_gl_context: --preview
    log::info("preview: {}", png.string());
  }
  if (!o.json) fmt::print("verdict: {}: {}\n", row.verdict, fmt::join(verdict.reasons, "; "));
  return o.strict && verdict.verdict != sampler::Verdict::Ok ? 1 : 0;
}

// Every mesh of a batch, a failure a row of the summary; returns the first failure's exit code.
int run_batch(const Options& o, const std::vector<std::string>& meshes, gpu::Context* context) {
  std::vector<BatchRow> rows;
  std::set<std::string> names;
  int first_code = 0, short_of_ok = 0;
  for (const std::string& path : meshes) {
    Options one = o;
    one.mesh = path;
    if (!rows.empty()) one.context_seconds = 0.0;  // the batch's one context counts with its first mesh
    BatchRow r;
    r.mesh = path;
    try {
      if (!names.insert(std::filesystem::path(path).stem().string()).second) {
        throw InputError(path, "another mesh of the batch has the same name; its outputs would overwrite");
      }
      r.exit_code = convert_one(one, context, r);
    } catch (const GpuError&) {
      throw;  // the context is gone: no later mesh can run
    } catch (const Error& e) {
      r.status = "failed", r.error = e.what(), r.exit_code = static_cast<int>(e.code());
      log::error("{}", e.what());
    }
    if (r.exit_code != 0 && first_code == 0) first_code = r.exit_code;
    if (r.status == "ok" && r.verdict != sampler::verdict_name(sampler::Verdict::Ok)) ++short_of_ok;
    rows.push_back(r);
  }
  const std::filesystem::path csv = summary_path(o);
  write_summary(csv, rows);
  if (!o.json) {
    const auto converted =
        std::count_if(rows.begin(), rows.end(), [](const BatchRow& r) { return r.status == "ok"; });
    fmt::print("{} of {} meshes converted, {} of them short of 'body OK'{}; summary: {}\n", converted,
               rows.size(), short_of_ok, o.strict && short_of_ok > 0 ? " (exit 1: --strict)" : "",
               csv.string());
  }
  return first_code;
}

// Whether a run needs a GL context at all: auto asks the device what it is, the GPU paths and
// --preview use it. `--backend cpu` without them runs everything on the CPU, the SDF included
// (--sdf-backend auto then means a CPU field, exact or OpenVDB's), so it works where EGL does not.
bool needs_gl_context(const Options& o) { return o.backend != "cpu" || o.sdf_backend == "gpu" || o.preview; }

int run_sample(Options& o, const GlobalOptions& global) {
  if (o.inputs.empty() && o.list.empty()) throw Error(ExitCode::Usage, "sample: give at least one MESH or --list FILE");
  if (!(Eigen::Vector3d(o.up[0], o.up[1], o.up[2]).norm() > 0.0))
    throw Error(ExitCode::Usage, "sample: --up must not be the zero vector");
  const std::vector<std::string> meshes = expand_inputs(o);
  o.batch = meshes.size() > 1 || !o.list.empty() || !o.shard.empty() || !o.summary.empty() ||
            (!o.inputs.empty() && o.inputs[0].rfind('@', 0) == 0);
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<gpu::Context> context;  // one context for the whole batch, if any stage needs one
  if (needs_gl_context(o)) context = std::make_unique<gpu::Context>(context_options(global));
  o.context_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (o.batch) return run_batch(o, meshes, context.get());
  o.mesh = meshes.front();
  BatchRow row;
  return convert_one(o, context.get(), row);
}

}  // namespace

Runner add_sample_command(CLI::App& app, const GlobalOptions& global) {
  return add_command<Options>(app, global, "sample",
                              "Convert a closed mesh into a particle rigid body (NAME.particles.ply + NAME.body.json)",
                              run_sample, add_input_options, add_sampling_options, add_solid_and_output_options);
}

}  // namespace ts::app
