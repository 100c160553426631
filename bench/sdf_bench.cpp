// SDF construction four ways on the same mesh, voxel size and band, in one run: tetrasand's GPU scan
// conversion by its geometry-shader path ("GPU" in the columns) and by its compute path ("compute"), the CPU
// exact SDF (triangle sweep, double precision, TBB on all cores) and OpenVDB's meshToLevelSet (all cores),
// with the error of the GPU path and of OpenVDB against exact distance. Usage:
//   tetrasand_bench_sdf CASE... [--band 3] [--csv FILE] [--markdown] [--openvdb-ridges]
// --openvdb-ridges also runs OpenVDB without its renormalisation pass and prints, per case, both
// against exact and how many voxels are off by one voxel exactly and sit on a distance ridge (the
// cause of OpenVDB's max error of exactly 1.000 voxel on armadillo; docs/benchmarks.md, sdf).
// CASE is MESH@R1,R2,... (a mesh file, or icosphere:S for a generated sphere of 20 * 4^S triangles)
// with the resolutions (voxels along the longest side) to run it at.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/mesh_cases.h"
#include "core/mesh_io.h"
#include "core/primitives.h"
#include "gpu/context.h"
#include "sdf/exact_sdf.h"
#include "sdf/grid.h"
#include "sdf/openvdb_compare.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"
#include "sdf/vdb_io.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

using Case = ts::bench::MeshCase;
using ts::bench::load_case_mesh;
using ts::bench::short_name;

struct Row {
  std::string mesh;
  std::size_t triangles = 0;
  int resolution = 0;
  Eigen::Vector3i dims;
  double gpu_s = 0, exact_s = 0, vdb_s = 0, compute_s = 0;
  std::size_t band_voxels = 0, slabs = 0, peak_gpu_bytes = 0;
  std::size_t compute_band_voxels = 0, compute_peak_gpu_bytes = 0;
  ts::sdf::GridComparison gpu, vdb, compute;  // against exact
};

// Voxels where OpenVDB is off by one voxel (to 1e-3), and how many of them lie less than 0.8 voxel
// outside the surface on a local maximum of the exact distance over their six neighbours.
void print_ridge_check(const ts::TriangleMesh& mesh, const ts::sdf::GridSpec& spec, const openvdb::FloatGrid& exact,
                       const openvdb::FloatGrid& vdb, double band, int resolution) {
  const double h = spec.voxel_size, band_world = band * h;
  const auto raw = ts::sdf::openvdb_level_set(mesh, h, band, /*renormalize=*/false);
  const auto with = ts::sdf::compare_grids(vdb, exact, h, band_world);
  const auto without = ts::sdf::compare_grids(*raw, exact, h, band_world);
  auto e = exact.getConstAccessor();
  auto v = vdb.getConstAccessor();
  std::size_t one_voxel = 0, on_ridge = 0;
  for (auto it = exact.cbeginValueOn(); it; ++it) {
    if (!(std::abs(*it) < band_world)) continue;
    if (std::abs(std::abs(static_cast<double>(v.getValue(it.getCoord())) - *it) / h - 1.0) > 1e-3) continue;
    ++one_voxel;
    bool ridge = *it > 0.0f && *it < 0.8 * h;
    for (const auto& o : {openvdb::Coord(1, 0, 0), openvdb::Coord(-1, 0, 0), openvdb::Coord(0, 1, 0),
                          openvdb::Coord(0, -1, 0), openvdb::Coord(0, 0, 1), openvdb::Coord(0, 0, -1)})
      ridge = ridge && e.getValue(it.getCoord() + o) <= *it;
    on_ridge += ridge ? 1 : 0;
  }
  fmt::print("OpenVDB renormalisation at {}: with it mean {:.4f} max {:.4f} voxels, {} wrong signs; without it mean "
             "{:.4f} max {:.4f}, {} wrong signs; {} voxels off by one voxel, {} of them on a distance ridge within "
             "0.8 voxel outside\n",
             resolution, with.mean, with.max, with.sign_disagreements, without.mean, without.max,
             without.sign_disagreements, one_voxel, on_ridge);
  std::fflush(stdout);
}

Row run_case(ts::gpu::Context& context, const ts::TriangleMesh& mesh, const ts::sdf::Pseudonormals& normals,
             int resolution, double band, bool ridges) {
  ts::sdf::SdfSettings settings;
  settings.resolution = resolution;
  settings.band = band;
  const ts::sdf::GridSpec spec = ts::sdf::make_grid(ts::bounding_box(mesh), settings);
  Row row;
  row.triangles = mesh.triangle_count();
  row.resolution = resolution;
  row.dims = spec.dims;
  ts::sdf::ScanConvertOptions options;
  options.band = band;
  options.method = ts::sdf::ScanMethod::Geometry;
  auto start = Clock::now();
  const auto gpu = ts::sdf::scan_convert(context, mesh, normals, spec, options);
  row.gpu_s = since(start);
  row.band_voxels = gpu.stats.band_voxels;
  row.slabs = static_cast<std::size_t>(gpu.stats.slabs);
  row.peak_gpu_bytes = gpu.stats.peak_gpu_bytes;
  options.method = ts::sdf::ScanMethod::Compute;
  start = Clock::now();
  const auto compute = ts::sdf::scan_convert(context, mesh, normals, spec, options);
  row.compute_s = since(start);
  row.compute_band_voxels = compute.stats.band_voxels;
  row.compute_peak_gpu_bytes = compute.stats.peak_gpu_bytes;
  start = Clock::now();
  const auto exact = ts::sdf::exact_sdf_grid(mesh, spec, band, ts::sdf::SignMethod::Pseudonormal);
  row.exact_s = since(start);
  start = Clock::now();
  const auto vdb = ts::sdf::openvdb_level_set(mesh, spec.voxel_size, band);
  row.vdb_s = since(start);
  const double band_world = band * spec.voxel_size;
  row.gpu = ts::sdf::compare_grids(*gpu.grid, *exact, spec.voxel_size, band_world);
  row.vdb = ts::sdf::compare_grids(*vdb, *exact, spec.voxel_size, band_world);
  row.compute = ts::sdf::compare_grids(*compute.grid, *exact, spec.voxel_size, band_world);
  if (ridges) print_ridge_check(mesh, spec, *exact, *vdb, band, resolution);
  return row;
}

void print_markdown_header() {
  fmt::print(
      "| mesh | triangles | grid | band voxels | GPU s | CPU exact s | OpenVDB s | exact / GPU | OpenVDB / "
      "GPU "
      "| GPU err mean / max (voxels) | OpenVDB err mean / p99 / max (voxels) | OpenVDB wrong signs "
      "| compute s | geometry / compute | compute err max (voxels) | compute wrong signs |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
}

void print_markdown_row(const Row& r) {
  fmt::print(
      "| {} | {} | {}x{}x{} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.1e} / {:.1e} | {:.4f} / "
      "{:.3f} / "
      "{:.3f} | {} | {:.2f} | {:.2f} | {:.1e} | {} |\n",
      r.mesh, r.triangles, r.dims.x(), r.dims.y(), r.dims.z(), r.band_voxels, r.gpu_s, r.exact_s, r.vdb_s,
      r.exact_s / r.gpu_s, r.vdb_s / r.gpu_s, r.gpu.mean, r.gpu.max, r.vdb.mean, r.vdb.p99, r.vdb.max,
      r.vdb.sign_disagreements, r.compute_s, r.gpu_s / r.compute_s, r.compute.max,
      r.compute.sign_disagreements);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<Case> cases;
    double band = 3.0;
    bool markdown = false, ridges = false;
    std::string csv_path;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--band" && i + 1 < argc) {
        band = std::stod(argv[++i]);
      } else if (arg == "--csv" && i + 1 < argc) {
        csv_path = argv[++i];
      } else if (arg == "--markdown") {
        markdown = true;
      } else if (arg == "--openvdb-ridges") {
        ridges = true;
      } else if (arg.rfind("--", 0) == 0) {
        throw std::runtime_error("unknown option " + arg);
      } else {
        cases.push_back(ts::bench::parse_mesh_case(arg));
      }
    }
    if (cases.empty()) throw std::runtime_error("usage: tetrasand_bench_sdf MESH@64,128... [--band 3] [--csv FILE] [--markdown] [--openvdb-ridges]");
    ts::sdf::ensure_openvdb_initialized();
    ts::gpu::Context context;
    fmt::print(stderr, "renderer: {}\n", context.summary());
    std::ofstream csv;
    if (!csv_path.empty()) {
      csv.open(csv_path);
      if (!csv) throw std::runtime_error("cannot write " + csv_path);
      csv << "mesh,triangles,resolution,nx,ny,nz,band_voxels,slabs,peak_gpu_mib,gpu_s,exact_s,openvdb_s,gpu_"
             "mean,gpu_p99,"
             "gpu_max,gpu_wrong_signs,openvdb_mean,openvdb_p99,openvdb_max,openvdb_wrong_signs,compute_s,"
             "compute_band_voxels,compute_peak_gpu_mib,compute_mean,compute_p99,compute_max,compute_wrong_"
             "signs\n";
    }
    if (markdown) print_markdown_header();
    for (const Case& c : cases) {
      const ts::TriangleMesh mesh = load_case_mesh(c.mesh);
      const ts::sdf::Pseudonormals normals = ts::sdf::compute_pseudonormals(mesh);
      fmt::print(stderr, "{}: {} triangles\n", c.mesh, mesh.triangle_count());
      // Warm-up: shader compilation is not part of any timing.
      for (const auto method : {ts::sdf::ScanMethod::Geometry, ts::sdf::ScanMethod::Compute}) {
        ts::sdf::SdfSettings warm;
        warm.resolution = 8;
        ts::sdf::ScanConvertOptions options;
        options.method = method;
        ts::sdf::scan_convert(
            context, ts::make_icosphere(0.5, 1), ts::sdf::compute_pseudonormals(ts::make_icosphere(0.5, 1)),
            ts::sdf::make_grid(ts::bounding_box(ts::make_icosphere(0.5, 1)), warm), options);
      }
      for (int resolution : c.resolutions) {
        Row r = run_case(context, mesh, normals, resolution, band, ridges);
        r.mesh = short_name(c.mesh);
        if (markdown) {
          print_markdown_row(r);
        } else {
          fmt::print(
              "{} {}^3 ({}x{}x{}): GPU (geometry) {:.3f} s, compute {:.3f} s, exact {:.3f} s, OpenVDB {:.3f} "
              "s; vs "
              "exact: geometry mean {:.2e} max {:.2e} ({} wrong signs), compute mean {:.2e} max {:.2e} ({} "
              "wrong "
              "signs, {} band voxels against {}), OpenVDB mean {:.4f} p99 {:.4f} max {:.3f} voxels, {} wrong "
              "signs\n",
              r.mesh, resolution, r.dims.x(), r.dims.y(), r.dims.z(), r.gpu_s, r.compute_s, r.exact_s,
              r.vdb_s, r.gpu.mean, r.gpu.max, r.gpu.sign_disagreements, r.compute.mean, r.compute.max,
              r.compute.sign_disagreements, r.compute_band_voxels, r.band_voxels, r.vdb.mean, r.vdb.p99,
              r.vdb.max, r.vdb.sign_disagreements);
          std::fflush(stdout);
        }
        if (csv) {
          csv << fmt::format(
                     "{},{},{},{},{},{},{},{},{:.1f},{:.4f},{:.4f},{:.4f},{:.3e},{:.3e},{:.3e},{},{:.5f},{:."
                     "5f},{:.5f},{}",
                     r.mesh, r.triangles, r.resolution, r.dims.x(), r.dims.y(), r.dims.z(), r.band_voxels,
                     r.slabs, r.peak_gpu_bytes / 1048576.0, r.gpu_s, r.exact_s, r.vdb_s, r.gpu.mean,
                     r.gpu.p99, r.gpu.max, r.gpu.sign_disagreements, r.vdb.mean, r.vdb.p99, r.vdb.max,
                     r.vdb.sign_disagreements)
              << fmt::format(",{:.4f},{},{:.1f},{:.3e},{:.3e},{:.3e},{}\n", r.compute_s,
                             r.compute_band_voxels, r.compute_peak_gpu_bytes / 1048576.0, r.compute.mean,
                             r.compute.p99, r.compute.max, r.compute.sign_disagreements);
          csv.flush();
        }
      }
    }
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
}
