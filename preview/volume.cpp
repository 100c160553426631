#include "preview/volume.h"

#include <fmt/format.h>

#include <cmath>

#include "core/error.h"
#include "sdf/exact_sdf.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"

namespace ts::preview {
namespace {

// The box of the voxels at or inside the zero level (the band's inner half encloses the inside, so
// the inactive inside tiles add nothing), grown by half a voxel; the whole box when there are none.
Aabb surface_box(const openvdb::FloatGrid& grid, const sdf::GridSpec& spec, const Aabb& fallback) {
  openvdb::CoordBBox inside;
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    if (*it <= 0.0f) inside.expand(it.getBoundingBox());
  }
  if (inside.empty()) return fallback;
  const openvdb::Coord lo = inside.min(), hi = inside.max();
  Aabb box;
  box.extend(spec.voxel_center(lo.x() - spec.index_offset.x(), lo.y() - spec.index_offset.y(), lo.z() - spec.index_offset.z()));
  box.extend(spec.voxel_center(hi.x() - spec.index_offset.x(), hi.y() - spec.index_offset.y(), hi.z() - spec.index_offset.z()));
  box.min.array() -= 0.5 * spec.voxel_size;
  box.max.array() += 0.5 * spec.voxel_size;
  return box;
}

SdfVolume make_volume(const openvdb::FloatGrid& grid, const sdf::GridSpec& spec, double band) {
  SdfVolume v;
  v.spec = spec;
  v.band = band;
  v.grid = sdf::to_nanovdb(grid);
  v.level_set = grid.copy();  // shares the tree
  v.band_voxels = grid.activeVoxelCount();
  v.surface = surface_box(grid, spec, v.world_box());
  return v;
}

}  // namespace

bool SdfVolume::inside_out() const {
  if (!level_set) return false;
  const openvdb::Coord corner(spec.index_offset.x(), spec.index_offset.y(), spec.index_offset.z());
  return level_set->tree().getValue(corner) < 0.0f;
}

Aabb SdfVolume::world_box() const {
  Aabb box;
  box.extend(spec.origin);
  box.extend(spec.voxel_center(spec.dims.x() - 1, spec.dims.y() - 1, spec.dims.z() - 1));
  return box;
}

SdfVolume volume_from_level_set(const openvdb::FloatGrid& grid, const std::filesystem::path& file) {
  const openvdb::math::Transform& transform = grid.transform();
  const openvdb::Vec3d size = transform.voxelSize();
  // A uniform scale plus a translation: index (i, j, k) -> origin + h (i, j, k).
  const openvdb::Vec3d e0 = transform.indexToWorld(openvdb::Vec3d(1, 0, 0)) - transform.indexToWorld(openvdb::Vec3d(0, 0, 0));
  const openvdb::Vec3d e1 = transform.indexToWorld(openvdb::Vec3d(0, 1, 0)) - transform.indexToWorld(openvdb::Vec3d(0, 0, 0));
  const double h = size[0];
  const bool axis_aligned = std::abs(e0[1]) + std::abs(e0[2]) + std::abs(e1[0]) + std::abs(e1[2]) <= 1e-9 * h && e0[0] > 0;
  if (!transform.isLinear() || !transform.hasUniformScale() || !axis_aligned || !(h > 0.0)) {
    throw InputError(file, "the level set's transform is not a uniform, axis-aligned scale (rotated, sheared or "
                           "frustum grids are not supported)");
  }
  const double background = std::abs(static_cast<double>(grid.background()));
  if (!(background > 0.0)) throw InputError(file, "the level set's background value is 0: no narrow band to ray-cast");
  // The march's trilinear reads and the shading's central differences take values up to a voxel from
  // the surface; a thinner band clamps them and the surface comes out stepped. `tetrasand sdf` writes
  // at least 1 voxel for the same reason.
  if (background < h * (1.0 - 1e-6)) {
    throw InputError(file, fmt::format("the level set's narrow band is {:.3g} voxels wide on each side (background {:.4g}, "
                                       "voxel {:.4g}), narrower than the 1 voxel the ray cast reads; rebuild it with "
                                       "a wider band (tetrasand sdf --band 3, or OpenVDB's half width)",
                                       background / h, background, h));
  }
  openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  if (box.empty()) throw InputError(file, "the level set has no active voxels: nothing to ray-cast");
  box.expand(2);
  sdf::GridSpec spec;
  spec.voxel_size = h;
  spec.dims = Eigen::Vector3i(box.dim().x(), box.dim().y(), box.dim().z());
  spec.index_offset = Eigen::Vector3i(box.min().x(), box.min().y(), box.min().z());
  const openvdb::Vec3d origin = transform.indexToWorld(box.min());
  spec.origin = Eigen::Vector3d(origin.x(), origin.y(), origin.z());
  return make_volume(grid, spec, background / h);
}

SdfVolume volume_from_mesh(gpu::Context& context, const TriangleMesh& mesh, const sdf::SdfSettings& settings) {
  const sdf::GridSpec spec = sdf::make_grid(bounding_box(mesh), settings);
  sdf::ScanConvertOptions scan;
  scan.band = settings.band;
  scan.index_space_grid = true;  // read by index on the GPU: any voxel size
  const sdf::ScanConvertResult result = sdf::scan_convert(context, mesh, sdf::compute_pseudonormals(mesh), spec, scan);
  if (settings.sign == sdf::SignMethod::Winding) sdf::resign_by_winding_number(*result.grid, sdf::ExactDistance(mesh), &spec);
  return make_volume(*result.grid, spec, settings.band);
}

SdfVolume volume_from_mesh_on_cpu(const TriangleMesh& mesh, const sdf::SdfSettings& settings) {
  const sdf::GridSpec spec = sdf::make_grid(bounding_box(mesh), settings);
  const sdf::ExactDistance exact(mesh);
  const openvdb::FloatGrid::Ptr grid =
      sdf::exact_sdf_grid(exact, mesh, spec, settings.band, settings.sign, true);
  return make_volume(*grid, spec, settings.band);
}

}  // namespace ts::preview
