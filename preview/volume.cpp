#include "preview/volume.h"

#include <fmt/format.h>
#include <openvdb/tools/Dense.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "sdf/pseudonormals.h"

namespace ts::preview {

Aabb SdfVolume::world_box() const {
  Aabb box;
  box.extend(spec.origin);
  box.extend(spec.voxel_center(spec.dims.x() - 1, spec.dims.y() - 1, spec.dims.z() - 1));
  return box;
}

SdfVolume volume_from_dense(const sdf::DenseSdf& dense, double band_voxels) {
  SdfVolume v;
  v.spec = dense.spec;
  v.band = band_voxels;
  v.distance.resize(dense.values.size());
  const float scale = static_cast<float>(1.0 / dense.spec.voxel_size), band = static_cast<float>(band_voxels);
  tbb::parallel_for(std::size_t{0}, v.distance.size(), [&](std::size_t i) {
    v.distance[i] = std::clamp(dense.values[i].w() * scale, -band, band);
  });
  return v;
}

SdfVolume volume_from_level_set(const openvdb::FloatGrid& grid, const std::filesystem::path& file, int max_side,
                                std::size_t max_voxels) {
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
  openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  box.expand(2);
  const openvdb::Coord dim = box.dim();
  const std::size_t voxels = static_cast<std::size_t>(dim.x()) * dim.y() * dim.z();
  if (max_side > 0 && std::max({dim.x(), dim.y(), dim.z()}) > max_side) {
    throw InputError(file, fmt::format("the level set spans {} x {} x {} voxels; this GPU's 3D textures hold at most {} "
                                       "per side",
                                       dim.x(), dim.y(), dim.z(), max_side));
  }
  if (voxels > max_voxels) {
    throw InputError(file, fmt::format("the level set spans {} x {} x {} voxels, above the preview's cap of {} voxels",
                                       dim.x(), dim.y(), dim.z(), max_voxels));
  }
  SdfVolume v;
  v.band = background / h;
  v.spec.voxel_size = h;
  v.spec.dims = Eigen::Vector3i(dim.x(), dim.y(), dim.z());
  v.spec.index_offset = Eigen::Vector3i(box.min().x(), box.min().y(), box.min().z());
  const openvdb::Vec3d origin = transform.indexToWorld(box.min());
  v.spec.origin = Eigen::Vector3d(origin.x(), origin.y(), origin.z());
  v.distance.resize(voxels);
  // LayoutXYZ: x fastest, exactly GridSpec::linear_index.
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, v.distance.data());
  openvdb::tools::copyToDense(grid, dense);
  const float scale = static_cast<float>(1.0 / h), band = static_cast<float>(v.band);
  tbb::parallel_for(std::size_t{0}, voxels, [&](std::size_t i) {
    v.distance[i] = std::clamp(v.distance[i] * scale, -band, band);
  });
  return v;
}

SdfVolume volume_from_mesh(gpu::Context& context, const TriangleMesh& mesh, const sdf::SdfSettings& settings) {
  const sdf::GridSpec spec = sdf::make_grid(bounding_box(mesh), settings);
  sdf::ScanConvertOptions scan;
  scan.band = settings.band;
  scan.keep_dense = true;
  scan.build_grid = false;
  const sdf::ScanConvertResult result = sdf::scan_convert(context, mesh, sdf::compute_pseudonormals(mesh), spec, scan);
  return volume_from_dense(result.dense, settings.band);
}

}  // namespace ts::preview
