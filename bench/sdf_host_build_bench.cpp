// The host's share of scan conversion: the band read back from the GPU built into the OpenVDB level
// set, by the one-accessor insertion tetrasand used until issue 43 (sdf::insert_band_serial) and by
// the parallel leaf build that replaced it (sdf::LevelSetBuilder, here not overlapped: build time
// alone), on the bands the GL device's scan conversion produced. Usage:
//   tetrasand_bench_sdf_host_build CASE... [--repeats 3] [--threads N]
// CASE is MESH@R1,R2,... as for tetrasand_bench_sdf (a mesh file, or icosphere:S). The bands are
// taken from the scan's own level set (its active voxels, slab by slab as the scan cut them), so both
// builders see the same slabs; the best of the repeats is reported, with ns a band voxel, and the two
// trees are checked to be the same leaf for leaf.
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/mesh_cases.h"
#include "core/mesh_io.h"
#include "core/primitives.h"
#include "gpu/context.h"
#include "sdf/grid.h"
#include "sdf/level_set_builder.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

using Case = ts::bench::MeshCase;
using ts::bench::load_case_mesh;
using ts::bench::short_name;

// The scan's band again, as the slabs it read back: slab indices and 4 floats a voxel (the distance
// in voxels last), the slabs `layers` z-layers deep.
struct Band {
  ts::sdf::GridSpec spec;
  int layers = 0;
  std::vector<int> z0;
  std::vector<std::vector<std::size_t>> voxels;
  std::vector<std::vector<float>> values;
};

Band band_of(const openvdb::FloatGrid& grid, const ts::sdf::GridSpec& spec, int layers) {
  Band b{spec, layers, {}, {}, {}};
  const std::size_t nx = static_cast<std::size_t>(spec.dims.x()),
                    layer = nx * static_cast<std::size_t>(spec.dims.y());
  std::vector<std::pair<std::size_t, float>> all;
  all.reserve(grid.activeVoxelCount());
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    const openvdb::Coord c =
        it.getCoord() - openvdb::Coord(spec.index_offset.x(), spec.index_offset.y(), spec.index_offset.z());
    all.emplace_back(static_cast<std::size_t>(c.z()) * layer + static_cast<std::size_t>(c.y()) * nx +
                         static_cast<std::size_t>(c.x()),
                     static_cast<float>(*it / spec.voxel_size));
  }
  std::sort(all.begin(), all.end());
  std::size_t next = 0;
  for (int z0 = 0; z0 < spec.dims.z(); z0 += layers) {
    const std::size_t base = static_cast<std::size_t>(z0) * layer,
                      end = base + static_cast<std::size_t>(layers) * layer;
    b.z0.push_back(z0);
    b.voxels.emplace_back();
    b.values.emplace_back();
    for (; next < all.size() && all[next].first < end; ++next) {
      b.voxels.back().push_back(all[next].first - base);
      b.values.back().insert(b.values.back().end(), {0.0f, 0.0f, 0.0f, all[next].second});
    }
  }
  return b;
}

template <typename Add>
std::pair<double, openvdb::FloatTree::Ptr> timed_build(const Band& band, float background, int repeats,
                                                       Add&& add) {
  double best = 1e300;
  openvdb::FloatTree::Ptr tree;
  for (int r = 0; r < repeats; ++r) {
    tree = std::make_shared<openvdb::FloatTree>(background);
    const auto start = Clock::now();
    add(*tree, band);
    best = std::min(best, since(start));
  }
  return {best, tree};
}

bool same_leaves(const openvdb::FloatTree& a, const openvdb::FloatTree& b) {
  if (a.leafCount() != b.leafCount() || a.activeVoxelCount() != b.activeVoxelCount()) return false;
  for (auto leaf = a.cbeginLeaf(); leaf; ++leaf) {
    const auto* other = b.probeConstLeaf(leaf->origin());
    if (!other || leaf->getValueMask() != other->getValueMask() ||
        std::memcmp(leaf->buffer().data(), other->buffer().data(), leaf->SIZE * sizeof(float)) != 0)
      return false;
  }
  return true;
}

void run_case(ts::gpu::Context& context, const Case& c, int repeats) {
  const ts::TriangleMesh mesh = load_case_mesh(c.mesh);
  const ts::sdf::Pseudonormals normals = ts::sdf::compute_pseudonormals(mesh);
  for (int resolution : c.resolutions) {
    ts::sdf::SdfSettings settings;
    settings.resolution = resolution;
    const ts::sdf::GridSpec spec = ts::sdf::make_grid(ts::bounding_box(mesh), settings);
    const auto scan = ts::sdf::scan_convert(context, mesh, normals, spec, {});
    const Band band = band_of(*scan.grid, spec, scan.stats.layers_per_slab);
    const float h = static_cast<float>(spec.voxel_size), background = scan.grid->background();
    const auto [serial_s, serial] =
        timed_build(band, background, repeats, [&](openvdb::FloatTree& tree, const Band& b) {
          for (std::size_t s = 0; s < b.z0.size(); ++s)
            ts::sdf::insert_band_serial(tree, b.spec, h, {b.z0[s], b.voxels[s], b.values[s]});
        });
    const auto [parallel_s, parallel] =
        timed_build(band, background, repeats, [&](openvdb::FloatTree& tree, const Band& b) {
          ts::sdf::LevelSetBuilder builder(tree, b.spec, h, /*overlapped=*/false);
          for (std::size_t s = 0; s < b.z0.size(); ++s) builder.add({b.z0[s], b.voxels[s], b.values[s]});
          builder.finish();
        });
    const double voxels = static_cast<double>(scan.stats.band_voxels);
    fmt::print(
        "| {} | {}x{}x{} ({}) | {} | {} | {:.3f} | {:.3f} | {:.1f} | {:.1f} | {:.1f} | {:.3f} | {} |\n",
        short_name(c.mesh), spec.dims.x(), spec.dims.y(), spec.dims.z(), resolution, scan.stats.band_voxels,
        scan.stats.slabs, serial_s, parallel_s, 1e9 * serial_s / voxels, 1e9 * parallel_s / voxels,
        serial_s / parallel_s, scan.stats.seconds, same_leaves(*serial, *parallel) ? "yes" : "NO");
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<Case> cases;
  int repeats = 3;
  std::size_t threads = 0;  // 0: TBB's default, every core
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--repeats" && i + 1 < argc) {
      repeats = std::max(1, std::stoi(argv[++i]));
    } else if (arg == "--threads" && i + 1 < argc) {
      threads = static_cast<std::size_t>(std::max(1, std::stoi(argv[++i])));
    } else if (arg.rfind("--", 0) == 0) {
      fmt::print(stderr, "usage: tetrasand_bench_sdf_host_build MESH@R1,R2... [--repeats N] [--threads N]\n");
      return 2;
    } else {
      cases.push_back(ts::bench::parse_mesh_case(arg));
    }
  }
  std::unique_ptr<tbb::global_control> limit;
  if (threads)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  ts::gpu::Context context;
  fmt::print(stderr, "renderer: {}; TBB threads: {}\n", context.summary(),
             tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  fmt::print(
      "| mesh | grid | band voxels | slabs | serial s | parallel s | serial ns/voxel | parallel ns/voxel | "
      "serial / parallel | scan s (whole call) | same tree "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Case& c : cases) run_case(context, c, repeats);
  return 0;
}
