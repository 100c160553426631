#include "app/sample_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <utility>
#include <vector>

#include "sampler/thin_features.h"

namespace ts::app {

namespace {

// The certificate: proven or not, its bound and lower figure, and where the deepest holes are.
void print_certificate_line(const sampler::SampleResult& result) {
  const sampler::CoverageCertificate& c = result.certificate;
  const double r = result.body.particle_radius;
  if (c.covered) {
    fmt::print(
        "  certificate      certified: every surface point lies within r of a particle centre; covering "
        "radius <= {:.3f} r (>= {:.3f} r), {} sub-triangles down to r / {:.0f}\n",
        c.covering_bound / r, c.covering_lower / r, c.evaluated, r / c.floor);
    return;
  }
  fmt::print(
      "  certificate      NOT certified: covering radius <= {:.3f} r (>= {:.3f} r); {} sub-triangles ({:.3g} "
      "m^2) not proven within r of a particle, in {}{} holes\n",
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

// Where the relaxation and the certificate ran, and why: "relaxation on the CPU, certificate on the GPU
// (auto: the GL device is llvmpipe, a software renderer; --backend gpu forces the GPU)".
std::string backend_text(const sampler::SampleResult& result, const std::string& reason) {
  const auto device = [](bool cpu) { return cpu ? "CPU" : "GPU"; };
  const std::string text =
      result.relax_on_cpu == result.certificate_on_cpu
          ? fmt::format("relaxation and certificate on the {}", device(result.relax_on_cpu))
          : fmt::format("relaxation on the {}, certificate on the {}", device(result.relax_on_cpu),
                        device(result.certificate_on_cpu));
  return fmt::format("{} ({})", text, reason);
}

// The stages of one mesh's run in the order they run, with their share of the command's time.
void print_stage_table(const sampler::SampleResult& result, const CommandSeconds& c) {
  const sampler::StageSeconds& t = result.stages;
  std::vector<std::pair<std::string, double>> rows{
      {"GPU context creation", c.context},
      {"mesh load and checks", c.load},
      {"plan: exact-distance tree, sizing, mass", t.plan},
      {result.field.gpu_resident
           ? fmt::format("SDF: {}, kept on the GPU", sdf_path_words(result.sdf_path).stage)
           : fmt::format("SDF: {}, NanoVDB{}", sdf_path_words(result.sdf_path).stage,
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
  if (c.preview) rows.emplace_back("preview (field, drawing, PNG)", *c.preview);
  fmt::print("{:<46} {:>9} {:>7}\n", "stage", "s", "share");
  for (const auto& [name, seconds] : rows) {
    fmt::print("{:<46} {:>9.3f} {:>6.1f}%\n", name, seconds, c.total > 0.0 ? 100.0 * seconds / c.total : 0.0);
  }
  fmt::print("{:<46} {:>9.3f}\n", "total (the command, this mesh)", c.total);
}

}  // namespace

// What this run cost and where it ran: the device, the SDF's path, the probes and each stage's seconds.
nlohmann::json run_json(const sampler::SampleResult& result, const CommandSeconds& c,
                        const gpu::Context* context) {
  const sampler::StageSeconds& t = result.stages;
  nlohmann::json run = {
      {"device", device_name(context)},
      {"software_device", context ? nlohmann::json(context->software()) : nlohmann::json(nullptr)},
      {"sdf_backend", sampler::sdf_path_name(result.sdf_path)},
      {"scan", result.sdf_path == sampler::SdfPath::Scan
                   ? nlohmann::json(sdf::scan_method_name(result.field.scan))
                   : nlohmann::json(nullptr)},
      {"relax_backend", result.relax_on_cpu ? "cpu" : "gpu"},
      {"certificate_backend", result.certificate_on_cpu ? "cpu" : "gpu"},
      {"probes", result.probes},
      {"certificate_passes", result.certificate_passes},
      // The field between the scan and the relaxation: readback_bytes counts field bytes only (the
      // band read back for the host's level set), not the few counters a scan reads besides.
      {"sdf",
       {{"band_voxels", result.field.band_voxels},
        {"gpu_bytes", result.field.gpu_bytes},
        {"host_bytes", result.field.host_bytes},
        {"readback_bytes", result.field.readback_bytes},
        {"gpu_resident", result.field.gpu_resident}}},
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
  if (c.preview) run["seconds"]["preview"] = *c.preview;
  return run;
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

void print_body_report(const ReportFacts& facts, const sampler::SampleResult& result,
                       const std::filesystem::path& json, const gpu::Context* context) {
  const body::ParticleBody& body = result.body;
  const auto& q = body.quality;
  fmt::print("{} -> {}\n", facts.mesh, json.string());
  const std::size_t surface = body.positions.size() - body.interior_count;
  fmt::print("  particles        {} of radius {:.6g} m on the surface (area estimate {}, {:+.1f} %)\n",
             surface, body.particle_radius, result.estimated_count,
             100.0 * (static_cast<double>(surface) / static_cast<double>(result.estimated_count) - 1.0));
  if (facts.fill) {
    fmt::print(
        "  interior         {} on an FCC lattice of spacing 2r (estimate from V - A r: {:.0f}); {} in all\n",
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
  const std::string sdf = result.sdf_path == sampler::SdfPath::Scan && !facts.scan.empty()
                              ? "by GPU " + facts.scan
                              : std::string(sdf_path_words(result.sdf_path).device);
  fmt::print("  device           {}: SDF {} {:.2f} s, relaxation {:.2f} s, certificate {:.2f} s; {}\n",
             device_name(context), sdf, t.sdf, t.relaxation, t.certificate, backend_text(result, facts.backend_reason));
  fmt::print(
      "  work             {} iterations, {} hole-closing rounds, {}, {:.2f} s on {} (certificate {:.2f} s in "
      "{} passes, probes {:.2f} s)\n",
      q.iterations, q.injection_rounds, q.converged ? "converged" : "NOT converged", q.seconds,
      device_name(context), result.certificate_seconds, result.certificate_passes, result.probe_seconds);
  fmt::print(
      "  mass properties  {:.6g} kg, volume {:.6g} m^3, centre of mass ({:.6g}, {:.6g}, {:.6g}) m, {}\n",
      body.mass, body.volume, body.center_of_mass.x(), body.center_of_mass.y(), body.center_of_mass.z(),
      body.mass_method == body::MassMethod::WindingCells
          ? fmt::format("from the winding-number solid (cells of {:.3g} m)", body.mass_cell)
          : std::string("from the closed mesh"));
}

void print_timings(const sampler::SampleResult& result, const CommandSeconds& c) {
  const sampler::FieldStats& f = result.field;
  const double per_voxel = f.band_voxels ? 1.0 / static_cast<double>(f.band_voxels) : 0.0;
  fmt::print(
      "sparse SDF: {} band voxels; GPU {:.1f} MiB ({:.1f} bytes a band voxel), host {:.1f} MiB ({:.1f} bytes "
      "a band voxel) at its peak, scan conversion {:.1f} MiB on the GPU and {:.1f} MiB read back\n",
      f.band_voxels, f.gpu_bytes / 1048576.0, static_cast<double>(f.gpu_bytes) * per_voxel,
      f.host_bytes / 1048576.0, static_cast<double>(f.host_bytes) * per_voxel,
      f.scan_peak_gpu_bytes / 1048576.0, f.readback_bytes / 1048576.0);
  fmt::print("{}", result.timing_report);
  print_stage_table(result, c);
}

}  // namespace ts::app
