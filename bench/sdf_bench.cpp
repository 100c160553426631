// SDF construction side by side on the same mesh and voxel size, in one run: tetrasand's GPU scan
// conversion against OpenVDB's meshToLevelSet (all cores), with their agreement in voxels. Usage:
//   tetrasand_bench_sdf MESH [--resolutions 64,128,256] [--band 3] [--markdown]
#include <fmt/format.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <chrono>
#include <sstream>
#include <string>
#include <vector>

#include "core/mesh_io.h"
#include "gpu/context.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

ts::sdf::GridSpec grid_for(const ts::TriangleMesh& mesh, int resolution, double band) {
  const ts::Aabb box = ts::bounding_box(mesh);
  ts::sdf::GridSpec s;
  s.voxel_size = box.size().maxCoeff() / resolution;
  const int padding = static_cast<int>(std::ceil(band)) + 1;
  for (int a = 0; a < 3; ++a) {
    s.index_offset[a] = static_cast<int>(std::floor(box.min[a] / s.voxel_size)) - padding;
    s.dims[a] = static_cast<int>(std::ceil(box.max[a] / s.voxel_size)) + padding - s.index_offset[a] + 1;
  }
  s.origin = s.voxel_size * s.index_offset.cast<double>();
  return s;
}

struct Agreement {
  double mean = 0, p99 = 0, max = 0;  // voxels
  std::size_t voxels = 0, sign_disagreements = 0;
};

Agreement agreement(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b, double h, double band) {
  std::vector<double> diffs;
  Agreement out;
  auto other = b.getConstAccessor();
  for (auto it = a.cbeginValueOn(); it; ++it) {
    const float va = *it, vb = other.getValue(it.getCoord());
    if (std::abs(va) >= band * h || std::abs(vb) >= band * h) continue;
    diffs.push_back(std::abs(va - vb) / h);
    out.sign_disagreements += (va < 0) != (vb < 0) ? 1 : 0;
  }
  if (diffs.empty()) return out;
  std::sort(diffs.begin(), diffs.end());
  out.voxels = diffs.size();
  for (double d : diffs) out.mean += d;
  out.mean /= static_cast<double>(diffs.size());
  out.p99 = diffs[static_cast<std::size_t>(0.99 * static_cast<double>(diffs.size() - 1))];
  out.max = diffs.back();
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 2) throw std::runtime_error("usage: tetrasand_bench_sdf MESH [--resolutions 64,128] [--band 3] [--markdown]");
    std::vector<int> resolutions{64, 128, 256};
    double band = 3.0;
    bool markdown = false;
    for (int i = 2; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--resolutions" && i + 1 < argc) {
        resolutions.clear();
        std::stringstream list(argv[++i]);
        for (std::string item; std::getline(list, item, ',');) resolutions.push_back(std::stoi(item));
      } else if (arg == "--band" && i + 1 < argc) {
        band = std::stod(argv[++i]);
      } else if (arg == "--markdown") {
        markdown = true;
      } else {
        throw std::runtime_error("unknown option " + arg);
      }
    }
    openvdb::initialize();
    const ts::TriangleMesh mesh = ts::load_mesh(argv[1]);
    ts::gpu::Context context;
    const ts::sdf::Pseudonormals normals = ts::sdf::compute_pseudonormals(mesh);
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    for (const auto& v : mesh.vertices) points.emplace_back(v.x(), v.y(), v.z());
    for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    fmt::print(stderr, "{}: {} triangles on {}\n", argv[1], mesh.triangle_count(), context.summary());
    if (markdown) {
      fmt::print("| mesh | grid | GPU scan conversion s | OpenVDB meshToLevelSet s | OpenVDB / GPU | band voxels | mean | p99 | max (voxels) | sign disagreements |\n");
      fmt::print("|---|---|---|---|---|---|---|---|---|---|\n");
    }
    for (int resolution : resolutions) {
      const ts::sdf::GridSpec spec = grid_for(mesh, resolution, band);
      ts::sdf::ScanConvertOptions options;
      options.band = band;
      ts::sdf::scan_convert(context, mesh, normals, grid_for(mesh, 16, band), options);  // warm-up: shader compile
      auto start = Clock::now();
      const auto gpu = ts::sdf::scan_convert(context, mesh, normals, spec, options);
      const double gpu_seconds = since(start);
      start = Clock::now();
      auto transform = openvdb::math::Transform::createLinearTransform(spec.voxel_size);
      const auto vdb = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*transform, points, triangles,
                                                                          static_cast<float>(band));
      const double vdb_seconds = since(start);
      const Agreement a = agreement(*gpu.grid, *vdb, spec.voxel_size, band);
      const std::string grid = fmt::format("{}x{}x{}", spec.dims.x(), spec.dims.y(), spec.dims.z());
      if (markdown) {
        fmt::print("| {} | {} | {:.3f} | {:.3f} | {:.2f} | {} | {:.4f} | {:.4f} | {:.3f} | {} |\n",
                   std::filesystem::path(argv[1]).filename().string(), grid, gpu_seconds, vdb_seconds,
                   vdb_seconds / gpu_seconds, a.voxels, a.mean, a.p99, a.max, a.sign_disagreements);
      } else {
        fmt::print("{:>14}: GPU {:.3f} s, OpenVDB {:.3f} s (ratio {:.2f}); |GPU - OpenVDB| mean {:.4f}, p99 {:.4f}, max {:.3f} voxels, {} sign disagreements over {} voxels\n",
                   grid, gpu_seconds, vdb_seconds, vdb_seconds / gpu_seconds, a.mean, a.p99, a.max,
                   a.sign_disagreements, a.voxels);
      }
    }
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
}
