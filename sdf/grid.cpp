#include "sdf/grid.h"

#include <fmt/format.h>

#include <cmath>

#include "core/error.h"

namespace ts::sdf {

GridSpec make_grid(const Aabb& box, const SdfSettings& s) {
  if (!box.valid() || !box.min.allFinite() || !box.max.allFinite()) {
    throw InputError("the mesh has no finite bounding box");
  }
  if (s.voxel_size < 0.0 || !std::isfinite(s.voxel_size)) {
    throw InputError(fmt::format("voxel size must be positive (got {})", s.voxel_size));
  }
  if (s.voxel_size == 0.0 && s.resolution < 1) {
    throw InputError(fmt::format("resolution must be at least 1 voxel (got {})", s.resolution));
  }
  if (!(s.band >= 1.0)) throw InputError(fmt::format("band half-width must be at least 1 voxel (got {})", s.band));
  if (s.padding < -1) throw InputError(fmt::format("padding must be >= 0 voxels (got {})", s.padding));
  const double longest = box.size().maxCoeff();
  const double h = s.voxel_size > 0.0 ? s.voxel_size : longest / s.resolution;
  if (!(h > 0.0)) throw InputError("the mesh is a single point: no voxel size follows from its bounding box");
  const int padding = s.padding >= 0 ? s.padding : static_cast<int>(std::ceil(s.band)) + 1;
  GridSpec spec;
  spec.voxel_size = h;
  Eigen::Vector3d dims;
  for (int a = 0; a < 3; ++a) {
    const double lo = std::floor(box.min[a] / h) - padding, hi = std::ceil(box.max[a] / h) + padding;
    if (std::abs(lo) > 2e9 || std::abs(hi) > 2e9) {
      throw InputError(fmt::format("voxel size {:.4g} is too small for coordinates of {:.4g}: the grid index "
                                   "overflows; move the mesh nearer the origin or use a larger voxel",
                                   h, std::max(std::abs(box.min[a]), std::abs(box.max[a]))));
    }
    spec.index_offset[a] = static_cast<int>(lo);
    dims[a] = hi - lo + 1;
  }
  const double voxels = dims.prod();
  if (voxels > static_cast<double>(s.max_voxels) || dims.maxCoeff() > 2e9) {
    // dims scale as 1/h: the smallest h that fits makes the product equal to the cap.
    const double smallest = h * std::cbrt(voxels / static_cast<double>(s.max_voxels)) * 1.01;
    const Eigen::Vector3d fits = (dims * (h / smallest)).array().floor();
    throw InputError(fmt::format("a {:.0f} x {:.0f} x {:.0f} grid ({:.3g} voxels) exceeds the cap of {} voxels; the "
                                 "largest grid that fits is about {:.0f} x {:.0f} x {:.0f}: the smallest voxel size "
                                 "that fits is about {:.4g} (resolution {:.0f})",
                                 dims.x(), dims.y(), dims.z(), voxels, s.max_voxels, fits.x(), fits.y(), fits.z(),
                                 smallest, std::floor(longest / smallest)));
  }
  spec.dims = dims.cast<int>();
  spec.origin = h * spec.index_offset.cast<double>();
  return spec;
}

}  // namespace ts::sdf
