#include "sdf/host_field.h"

#include <cmath>

#include "core/error.h"

namespace ts::sdf {
namespace {

// GLSL's mix(a, b, t) = a (1 - t) + b t, written as GLSL defines it so the weights are the same.
double mix(double a, double b, double t) { return a * (1.0 - t) + b * t; }

// The eight corners of the voxel cell holding `x`, combined as field_trilinear combines them.
// `voxel(g)` reads grid-local voxel g.
template <class Voxel>
double trilinear(const Eigen::Vector3d& x, Voxel&& voxel) {
  const Eigen::Vector3d base = x.array().floor().matrix();
  const Eigen::Vector3d t = x - base;
  const Eigen::Vector3i g = base.cast<int>();
  const double c000 = voxel(g);
  const double c100 = voxel(g + Eigen::Vector3i(1, 0, 0));
  const double c010 = voxel(g + Eigen::Vector3i(0, 1, 0));
  const double c110 = voxel(g + Eigen::Vector3i(1, 1, 0));
  const double c001 = voxel(g + Eigen::Vector3i(0, 0, 1));
  const double c101 = voxel(g + Eigen::Vector3i(1, 0, 1));
  const double c011 = voxel(g + Eigen::Vector3i(0, 1, 1));
  const double c111 = voxel(g + Eigen::Vector3i(1, 1, 1));
  const double c00 = mix(c000, c100, t.x()), c10 = mix(c010, c110, t.x());
  const double c01 = mix(c001, c101, t.x()), c11 = mix(c011, c111, t.x());
  return mix(mix(c00, c10, t.y()), mix(c01, c11, t.y()), t.z());
}

double read_voxel(FieldAccessor& accessor, const Eigen::Vector3i& index_offset, const Eigen::Vector3i& g) {
  const Eigen::Vector3i ijk = g + index_offset;
  return accessor.getValue(nanovdb::Coord(ijk.x(), ijk.y(), ijk.z()));
}

// The voxels from `lo` to lo + 2 along each axis, read once: every corner of the seven trilinear
// reads of one sample. A corner outside it (possible only when rounding puts floor(x + 0.5) two
// voxels above floor(x - 0.5)) is read from the grid directly.
class VoxelBlock {
 public:
  VoxelBlock(FieldAccessor& accessor, const Eigen::Vector3i& index_offset, const Eigen::Vector3i& lo)
      : accessor_(accessor), index_offset_(index_offset), lo_(lo) {
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
          values_[i + 3 * (j + 3 * k)] = read_voxel(accessor, index_offset, lo + Eigen::Vector3i(i, j, k));
  }

  double operator()(const Eigen::Vector3i& g) const {
    const Eigen::Vector3i d = g - lo_;
    if ((d.array() < 0).any() || (d.array() > 2).any()) return read_voxel(accessor_, index_offset_, g);
    return values_[d.x() + 3 * (d.y() + 3 * d.z())];
  }

 private:
  FieldAccessor& accessor_;
  Eigen::Vector3i index_offset_, lo_;
  double values_[27];
};

}  // namespace

double sparse_trilinear(FieldAccessor& accessor, const Eigen::Vector3i& index_offset,
                        const Eigen::Vector3d& x) {
  return trilinear(x, [&](const Eigen::Vector3i& g) { return read_voxel(accessor, index_offset, g); });
}

HostField::HostField(NanoGrid grid, const GridSpec& spec, double band_voxels)
    : spec_(spec),
      band_(band_voxels),
      background_(static_cast<float>(band_voxels * spec.voxel_size)),
      host_(std::move(grid)),
      grid_(host_.grid<float>()) {
  if (!grid_) throw Error(ExitCode::Internal, "HostField: the NanoVDB grid is not a float grid");
  band_voxels_ = grid_->activeVoxelCount();
}

FieldSample HostField::sample(FieldAccessor& accessor, const Eigen::Vector3d& p) const {
  const double h = spec_.voxel_size;
  const Eigen::Vector3d x = p / h;
  const Eigen::Vector3i lo = (x - Eigen::Vector3d::Constant(0.5)).array().floor().cast<int>().matrix();
  const VoxelBlock block(accessor, spec_.index_offset, lo);
  const auto at = [&](const Eigen::Vector3d& y) { return trilinear(y, block); };
  FieldSample s;
  s.value = at(x);
  const Eigen::Vector3d dx(0.5, 0.0, 0.0), dy(0.0, 0.5, 0.0), dz(0.0, 0.0, 0.5);
  const Eigen::Vector3d gradient(at(x + dx) - at(x - dx), at(x + dy) - at(x - dy), at(x + dz) - at(x - dz));
  const double length = gradient.norm();
  if (length > 1e-6 * h) s.normal = gradient / length;
  return s;
}

}  // namespace ts::sdf
