// `tetrasand sdf MESH -o OUT.vdb`: narrow-band SDF by GPU scan conversion or the exact CPU path (chosen
// by --backend and the one rule of gpu/backend.h), written as an OpenVDB level set.
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cctype>
#include <chrono>
#include <memory>

#include <nlohmann/json.hpp>
#include <openvdb/tools/SignedFloodFill.h>

#include "app/commands.h"
#include "app/numeric_options.h"
#include "app/progress.h"
#include "app/sdf_report.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/mesh_io.h"
#include "gpu/backend.h"
#include "sdf/exact_sdf.h"
#include "sdf/grid.h"
#include "sdf/mesh_signs.h"
#include "sdf/openvdb_compare.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_calibration.h"
#include "sdf/scan_convert.h"
#include "sdf/sparse_field.h"
#include "sdf/vdb_io.h"

namespace ts::app {

namespace {

using Options = SdfOptions;
using Figures = SdfFigures;

// The suffix chooses the file format: OpenVDB (.vdb) or NanoVDB (.nvdb), case-insensitive.
bool is_nanovdb_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".vdb" && ext != ".nvdb") {
    throw Error(ExitCode::Usage, fmt::format("-o {}: the output must end in .vdb (OpenVDB) or .nvdb (NanoVDB)", path));
  }
  return ext == ".nvdb";
}


void add_options(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.mesh, "Closed triangle mesh (any format assimp reads)")->required();
  cmd->add_option("-o,--output", o.output, "Output file: .vdb (OpenVDB level set) or .nvdb (NanoVDB)")->required();
  auto* voxel = cmd->add_option("--voxel", o.voxel, "Voxel size [world units, m]")->check(positive());
  cmd->add_option("--resolution", o.resolution, "Voxels along the longest side (instead of --voxel)")
      ->check(positive())
      ->excludes(voxel)
      ->capture_default_str();
  cmd->add_option(
         "--band", o.band,
         "Half-width of the narrow band [voxels], >= 1 (3: OpenVDB's default; 1 scans 2-3x faster when only "
         "the zero crossing is needed, docs/benchmarks.md Defaults)")
      ->check(finite())
      ->capture_default_str();
  cmd->add_option("--padding", o.padding, "Voxels beyond the bounding box (default: band + 1)")
      ->check(finite());
  cmd->add_option(
         "--backend", o.backend,
         "gpu: scan conversion on the GL device; cpu: the exact SDF (a sweep over the triangles, double "
         "precision, TBB on every core; no GL device needed); auto: cpu on a software renderer (on llvmpipe "
         "4-7x faster, docs/benchmarks.md SDF), gpu on a hardware GPU")
      ->check(CLI::IsMember({"auto", "gpu", "cpu"}))
      ->capture_default_str();
  cmd->add_option("--scan", o.scan,
                  "How the GPU scan conversion reaches the voxels: compute (triangle/brick pairs in compute "
                  "shaders, every core of the GPU), geometry (prisms sliced by a geometry shader and "
                  "rasterised: the thesis's method) or auto (compute, unless a calibration cached for this "
                  "renderer and driver found geometry faster; --backend gpu)")
      ->check(CLI::IsMember({"auto", "compute", "geometry"}))
      ->capture_default_str();
  cmd->add_option("--nvdb-codec", o.nvdb_codec,
                  "Compression of a .nvdb output: zip (smallest), blosc or none; NanoVDB's own codecs, read by "
                  "nanovdb_validate and tetrasand alike")
      ->check(CLI::IsMember({"none", "zip", "blosc"}))
      ->capture_default_str();
  cmd->add_option("--sign", o.sign, "Sign method: pseudonormal (closed meshes) or winding (robust to holes)")
      ->check(CLI::IsMember({"pseudonormal", "winding"}))
      ->capture_default_str();
  cmd->add_option("--scale", o.scale, "Multiply coordinates by this factor first (e.g. 1000: metres -> mm)")
      ->check(positive());
  cmd->add_option("--max-slab-mb", o.slab_mb, "GPU memory for one z-slab of the grid [MiB] (--backend gpu)")
      ->check(positive())
      ->capture_default_str();
  cmd->add_flag("--timings", o.timings,
                "Per-kernel GPU times and peak GPU memory (--backend gpu), memory per band voxel");
  cmd->add_flag("--json", o.json, "Print the run's figures (grid, band voxels, memory per band voxel, times) as JSON");
  cmd->add_flag(
      "--compare-openvdb", o.compare,
      "Also build OpenVDB's meshToLevelSet and the exact SDF; print how both compare with exact distance "
      "(--backend gpu)");
}

// The mesh, scaled, with a warning where its signs cannot be trusted.
TriangleMesh load_sdf_mesh(const Options& o) {
  TriangleMesh mesh = load_mesh(o.mesh);
  if (o.scale != 1.0) scale_mesh(mesh, o.scale);
  sdf::warn_about_signs(mesh, o.mesh, o.sign == "winding" ? sdf::SignMethod::Winding : sdf::SignMethod::Pseudonormal);
  return mesh;
}

sdf::GridSpec grid_of(const Options& o, const TriangleMesh& mesh) {
  sdf::SdfSettings settings;
  settings.voxel_size = o.voxel;
  settings.resolution = o.resolution;
  settings.band = o.band;
  settings.padding = o.padding;
  const sdf::GridSpec spec = sdf::make_grid(bounding_box(mesh), settings);
  if (o.padding >= 0 && o.padding < o.band) {
    log::warn("{}: --padding {} is below the band half-width {}: the band is cut where the mesh comes within {} "
              "voxels of the grid border",
              o.mesh, o.padding, o.band, o.band);
  }
  return spec;
}

// Writes the level set in the format the suffix asks for; returns the size of its NanoVDB form (the
// GPU field's) when it was made or `measure` asks for it, else 0. *seconds: the write's time (for
// .nvdb the conversion to NanoVDB with it; the measurement for .vdb not).
std::size_t write_level_set(const Options& o, const sdf::ScanConvertResult& result, const std::string& device,
                            bool measure, double* seconds) {
  const auto start = std::chrono::steady_clock::now();
  auto lap = [&] {
    *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  if (is_nanovdb_path(o.output)) {
    sdf::NanoGrid nano = sdf::to_nanovdb(*result.grid);
    sdf::write_nvdb(o.output, nano, {o.mesh}, sdf::parse_nvdb_codec(o.nvdb_codec).value());
    lap();
    return nano.size();
  }
  const std::map<std::string, std::string> metadata{{"tetrasand:source", o.mesh},
                                                    {"tetrasand:source_sha256", sha256_file(o.mesh)},
                                                    {"tetrasand:band_voxels", fmt::format("{}", o.band)},
                                                    {"tetrasand:sign", o.sign},
                                                    {"tetrasand:renderer", device}};
  sdf::write_vdb(o.output, result.grid, metadata, {o.mesh});
  lap();
  return measure ? sdf::to_nanovdb(*result.grid).size() : 0;
}

// The GPU path: scan conversion on the GL device, signs by winding number afterwards where asked.
// *device: the GL device's summary.
sdf::ScanConvertResult gpu_level_set(const Options& o, gpu::Context& context, const TriangleMesh& mesh,
                                     const sdf::GridSpec& spec, std::string* device) {
  *device = context.summary();
  sdf::ScanConvertOptions scan;
  scan.method = sdf::parse_scan_method(o.scan).value();  // CLI::IsMember checked the spelling
  scan.band = o.band;
  scan.timings = o.timings;
  scan.pipeline_statistics = o.timings;
  scan.max_slab_bytes = static_cast<std::size_t>(o.slab_mb * 1048576.0);
  Progress progress;  // a tenth of the grid a line in a pipe
  scan.progress = [&progress](double done) {
    progress.update(fmt::format("scan conversion {:5.1f} %", 100.0 * done), done);
  };
  const sdf::Pseudonormals normals = sdf::compute_pseudonormals(mesh);
  sdf::ScanConvertResult result =
      naming_file(o.mesh, [&] { return sdf::scan_convert(context, mesh, normals, spec, scan); });
  progress.end();
  // The winding-number signs replace the pseudonormal ones where the mesh cannot give them.
  if (o.sign == "winding") sdf::resign_by_winding_number(*result.grid, sdf::ExactDistance(mesh));
  return result;
}

// The CPU path: the exact SDF (sdf/exact_sdf.h) on every core, timed from the AABB tree's build to
// the flood-filled level set. *device: what ran it.
sdf::ScanConvertResult cpu_level_set(const Options& o, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                                     std::string* device) {
  *device = fmt::format("CPU exact SDF (triangle sweep, double precision, {} TBB threads)",
                        tbb::this_task_arena::max_concurrency());
  const auto start = std::chrono::steady_clock::now();
  sdf::ScanConvertResult result;
  result.grid = naming_file(o.mesh, [&] {
    return sdf::exact_sdf_grid(
        mesh, spec, o.band, o.sign == "winding" ? sdf::SignMethod::Winding : sdf::SignMethod::Pseudonormal);
  });
  result.stats.band_voxels = result.grid->activeVoxelCount();
  result.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

// The scan conversion as the backend line names it: "scan conversion by compute shaders".
std::string scan_words(const std::string& scan) {
  return sdf::parse_scan_method(scan).value() == sdf::ScanMethod::Compute
             ? "scan conversion by compute shaders"
             : "scan conversion by geometry shader";
}

// The backend line's note on the GPU path: why this scan method (`asked`: the --scan spelling, `o`
// the resolved run), and --compare-openvdb's reason.
std::string scan_note(const std::string& asked, const Options& o) {
  std::string note = asked == "auto" ? "--scan auto: " + o.scan_reason : "--scan " + asked + " asked for";
  if (o.compare && o.backend == "auto") note += "; --compare-openvdb compares the GPU field";
  return note;
}

// Where the field is built (gpu/backend.h): the options with `backend` set to the path that runs, and
// the GL context when that is the GPU. --compare-openvdb asks for the scan conversion (it compares the
// GPU field with the exact one). Prints the backend line (a log line under --json: standard output
// stays the JSON).
Options choose_backend(const Options& o, const GlobalOptions& global, std::unique_ptr<gpu::Context>& context) {
  gpu::Backend requested = gpu::parse_backend(o.backend).value();  // CLI::IsMember checked the spelling
  if (o.compare && requested == gpu::Backend::Cpu) {
    throw Error(
        ExitCode::Usage,
        "--compare-openvdb compares the GPU field with the exact one; with --backend cpu the field is the "
        "exact one");
  }
  if (o.compare) requested = gpu::Backend::Gpu;
  if (requested != gpu::Backend::Cpu) context = std::make_unique<gpu::Context>(context_options(global));
  const gpu::Backend chosen = gpu::resolve_backend(requested, context.get());
  Options run = o;
  run.backend = gpu::backend_name(chosen);
  if (chosen == gpu::Backend::Gpu) {
    // --scan auto: the cached calibration of this renderer and driver, or a calibration now.
    const sdf::ScanChoice scan = sdf::choose_scan(*context, o.scan);
    run.scan = sdf::scan_method_name(scan.method);
    run.scan_reason = scan.reason;
  }
  const std::string line = gpu::backend_line(requested, chosen, gpu::describe(context.get()), true,
                                             chosen == gpu::Backend::Cpu ? "exact SDF" : scan_words(run.scan),
                                             chosen == gpu::Backend::Cpu ? "" : scan_note(o.scan, run));
  if (o.json) {
    log::info("{}", line);
  } else {
    fmt::print("{}\n", line);
  }
  if (chosen == gpu::Backend::Cpu) context.reset();
  return run;
}

int run_sdf(const Options& options, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  is_nanovdb_path(options.output);  // a wrong suffix is a usage error before any work
  std::unique_ptr<gpu::Context> context;
  const Options o = choose_backend(options, global, context);
  const TriangleMesh mesh = load_sdf_mesh(o);
  const sdf::GridSpec spec = naming_file(o.mesh, [&] { return grid_of(o, mesh); });
  std::string device;
  sdf::ScanConvertResult result = o.backend == "cpu" ? cpu_level_set(o, mesh, spec, &device)
                                                     : gpu_level_set(o, *context, mesh, spec, &device);
  Figures figures{result.stats.band_voxels, result.grid->memUsage(), 0, result.stats.peak_gpu_bytes,
                  result.stats.readback_bytes, result.stats.seconds, 0.0, 0.0};
  figures.nanovdb_bytes = write_level_set(o, result, device, o.timings || o.json, &figures.write_seconds);
  figures.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (o.json) {
    print_sdf_json(o, mesh, spec, result.stats, figures, device);
    return 0;
  }
  print_sdf_summary(o, mesh, spec, result.stats);
  fmt::print("device: {}; {} {:.3f} s\n", device,
             o.backend == "cpu"
                 ? "exact SDF"
                 : fmt::format("scan {} ({})", sdf::scan_method_name(result.stats.method), o.scan_reason),
             result.stats.seconds);
  if (o.timings) {
    print_sdf_times(o, result.stats, figures);
    print_sdf_figures(o, figures);
  }
  if (o.compare) print_sdf_comparison(o, mesh, spec, result);
  fmt::print("total {:.2f} s\n",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return 0;
}

}  // namespace

Runner add_sdf_command(CLI::App& app, const GlobalOptions& global) {
  return add_command<Options>(
      app, global, "sdf",
      "Narrow-band signed distance field by GPU scan conversion or the exact CPU path (OpenVDB level set)",
      run_sdf, add_options);
}

}  // namespace ts::app
