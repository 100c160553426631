#include "sdf/openvdb_compare.h"

#include <fmt/format.h>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/ValueTransformer.h>

#include <algorithm>
#include <vector>

#include "sdf/vdb_io.h"

namespace ts::sdf {
namespace {

// The mesh as OpenVDB takes it: float points (each coordinate times `scale`, in double first) and
// index triples.
struct OpenVdbMesh {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
};
OpenVdbMesh to_openvdb_mesh(const TriangleMesh& mesh, double scale) {
  OpenVdbMesh m;
  m.points.reserve(mesh.vertex_count());
  m.triangles.reserve(mesh.triangle_count());
  for (const auto& v : mesh.vertices) {
    m.points.emplace_back(static_cast<float>(v.x() * scale), static_cast<float>(v.y() * scale),
                          static_cast<float>(v.z() * scale));
  }
  for (const auto& t : mesh.triangles) m.triangles.emplace_back(t[0], t[1], t[2]);
  return m;
}

}  // namespace

openvdb::FloatGrid::Ptr openvdb_level_set(const TriangleMesh& mesh, double h, double band, bool renormalize) {
  ensure_openvdb_initialized();
  // OpenVDB works in float world coordinates; the transform carries the voxel size.
  auto [points, triangles] = to_openvdb_mesh(mesh, 1.0);
  const auto transform = openvdb::math::Transform::createLinearTransform(h);
  if (renormalize) return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*transform, points, triangles, static_cast<float>(band));
  // What meshToLevelSet does, with the renormalisation pass switched off: points to index space first.
  std::vector<openvdb::Vec3s> index_points;
  index_points.reserve(points.size());
  for (const auto& p : points) index_points.emplace_back(transform->worldToIndex(openvdb::Vec3d(p)));
  openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(index_points, triangles);
  return openvdb::tools::meshToVolume<openvdb::FloatGrid>(adapter, *transform, static_cast<float>(band), static_cast<float>(band),
                                                          openvdb::tools::DISABLE_RENORMALIZATION);
}

openvdb::FloatGrid::Ptr openvdb_index_level_set(const TriangleMesh& mesh, const GridSpec& spec, double band_voxels) {
  ensure_openvdb_initialized();
  const double h = spec.voxel_size;
  // Voxel centres sit at integer coordinates (make_grid: origin = h * index_offset).
  const OpenVdbMesh m = to_openvdb_mesh(mesh, 1.0 / h);
  openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(m.points, m.triangles);
  // Voxel size 1 throughout, so OpenVDB's smallest voxel (about 1.3e-5) never applies; distances come
  // out in voxels and are scaled to world units after.
  const auto unit = openvdb::math::Transform::createLinearTransform(1.0);
  const float band = static_cast<float>(band_voxels);
  openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(adapter, *unit, band, band);
  const float scale = static_cast<float>(h);
  openvdb::tools::foreach(grid->beginValueOn(), [scale](const openvdb::FloatGrid::ValueOnIter& it) { it.setValue(*it * scale); });
  openvdb::tools::changeLevelSetBackground(grid->tree(), band * scale);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->setName("surface");
  return grid;
}

GridComparison compare_grids(const openvdb::FloatGrid& a, const openvdb::FloatGrid& reference, double voxel_size,
                             double band_world) {
  GridComparison out;
  std::vector<double> diffs;
  auto add = [&](float v, float r) {
    diffs.push_back(std::abs(static_cast<double>(v) - r) / voxel_size);
    // On the surface itself (|d| below 1e-4 voxel) the sign is a matter of rounding, not an error.
    if (std::abs(r) > 1e-4 * voxel_size) out.sign_disagreements += (v < 0) != (r < 0) ? 1 : 0;
  };
  auto in_band = [&](float value) { return std::abs(value) < band_world; };
  auto other = a.getConstAccessor();
  for (auto it = reference.cbeginValueOn(); it; ++it)
    if (in_band(*it)) add(other.getValue(it.getCoord()), *it);
  // Band voxels of `a` the reference has outside its band (or not at all): a's band is too wide there.
  auto ref = reference.getConstAccessor();
  for (auto it = a.cbeginValueOn(); it; ++it) {
    if (!in_band(*it)) continue;
    float r = 0.0f;
    if (ref.probeValue(it.getCoord(), r) && in_band(r)) continue;  // counted above
    add(*it, ref.getValue(it.getCoord()));
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

ThreeWayComparison compare_with_exact(const openvdb::FloatGrid& gpu, const openvdb::FloatGrid& openvdb,
                                      const openvdb::FloatGrid& exact, double voxel_size, double band_world) {
  return {compare_grids(gpu, exact, voxel_size, band_world), compare_grids(openvdb, exact, voxel_size, band_world),
          compare_grids(gpu, openvdb, voxel_size, band_world)};
}

std::string format_comparison(const ThreeWayComparison& c) {
  return format_comparison(c.gpu_vs_exact, c.openvdb_vs_exact, c.gpu_vs_openvdb);
}

std::string format_comparison(const GridComparison& gpu, const GridComparison& vdb, const GridComparison& both) {
  auto row = [](const char* name, const GridComparison& c) {
    return fmt::format("{:<24} {:>10} {:>12.3e} {:>12.3e} {:>10.3e} {:>8}\n", name, c.voxels, c.mean, c.p99, c.max,
                       c.sign_disagreements);
  };
  std::string s = fmt::format("{:<24} {:>10} {:>12} {:>12} {:>10} {:>8}\n", "|difference| in voxels", "voxels", "mean",
                              "p99", "max", "signs");
  s += row("tetrasand GPU vs exact", gpu);
  s += row("OpenVDB vs exact", vdb);
  s += row("tetrasand GPU vs OpenVDB", both);
  const bool gpu_closer = gpu.mean < vdb.mean || (gpu.mean == vdb.mean && gpu.max <= vdb.max);
  s += fmt::format("closer to exact: {} (mean {:.5f} vs {:.5f} voxels, {} vs {} wrong signs)\n",
                   gpu_closer ? "tetrasand GPU" : "OpenVDB", gpu.mean, vdb.mean, gpu.sign_disagreements,
                   vdb.sign_disagreements);
  return s;
}

}  // namespace ts::sdf
