#include "preview/cpu_field.h"

#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ts::preview {

CpuField::CpuField(const SdfVolume& volume) : spec_(volume.spec), band_(volume.band) {
  if (!volume.level_set || volume.level_set->empty() || spec_.dims.minCoeff() < 2) {
    throw InputError("the SDF to preview is empty or smaller than 2 voxels along an axis");
  }
  // Shares the tree; only the copy's metadata and transform change.
  grid_ = openvdb::ConstPtrCast<openvdb::FloatGrid>(volume.level_set)->copy();
  grid_->setTransform(openvdb::math::Transform::createLinearTransform(spec_.voxel_size));
  grid_->setGridClass(openvdb::GRID_LEVEL_SET);
  intersector_ = std::make_shared<const Intersector>(*grid_);
}

Eigen::Vector3d CpuField::to_voxel(const Eigen::Vector3d& world) const {
  return (world - spec_.origin) / spec_.voxel_size;
}

CpuField::Reader::Reader(const CpuField& field)
    : field_(field), accessor_(field.grid_->getConstAccessor()), intersector_(*field.intersector_) {}

double CpuField::Reader::sdf_at(const Eigen::Vector3d& u) {
  const Eigen::Vector3i& offset = field_.spec_.index_offset;
  const openvdb::Vec3R index(u.x() + offset.x(), u.y() + offset.y(), u.z() + offset.z());
  const double d = openvdb::tools::BoxSampler::sample(accessor_, index) / field_.spec_.voxel_size;
  return std::clamp(d, -field_.band_, field_.band_);
}

Eigen::Vector3d CpuField::Reader::normal(const Eigen::Vector3d& u) {
  Eigen::Vector3d g;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
    g[axis] = sdf_at(u + e) - sdf_at(u - e);
  }
  const double length = g.norm();
  return length > 1e-12 ? Eigen::Vector3d(g / length) : Eigen::Vector3d::UnitZ();
}

double CpuField::Reader::occlusion(const Eigen::Vector3d& u, const Eigen::Vector3d& n) {
  // How much the field, sampled outward along the normal, falls short of the distance travelled.
  double occluded = 0.0, weight = 0.5;
  for (int k = 1; k <= 4; ++k) {
    const double delta = 0.25 * k * field_.band_;
    occluded += weight * std::clamp((delta - sdf_at(u + n * delta)) / delta, 0.0, 1.0);
    weight *= 0.5;
  }
  return occluded;
}

std::optional<double> CpuField::Reader::first_crossing(const Eigen::Vector3d& o, const Eigen::Vector3d& dir,
                                                       double t0, double t1) {
  const Eigen::Vector3d eye = o + field_.spec_.index_offset.cast<double>();
  const Intersector::RayType ray(Intersector::Vec3Type(eye.x(), eye.y(), eye.z()),
                                 Intersector::Vec3Type(dir.x(), dir.y(), dir.z()), t0, t1);
  // The overload with the hit point: OpenVDB 10's intersectsIS(ray, time) reads the time before it
  // searches, so it returns the previous ray's.
  Intersector::Vec3Type hit;
  double t = 0.0;
  if (!intersector_.intersectsIS(ray, hit, t)) return std::nullopt;
  return refine(o, dir, std::max(t - 1.0, t0), std::min(t + 1.0, t1)).value_or(t);
}

std::optional<double> CpuField::Reader::refine(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, double a,
                                               double b) {
  double fa = sdf_at(o + a * dir), fb = sdf_at(o + b * dir);
  if (!(fa > 0.0 && fb <= 0.0)) return std::nullopt;
  for (int k = 0; k < 6; ++k) {
    const double m = a + (b - a) * std::clamp(fa / (fa - fb), 0.1, 0.9);
    const double fm = sdf_at(o + m * dir);
    if (fm > 0.0) {
      a = m;
      fa = fm;
    } else {
      b = m;
      fb = fm;
    }
  }
  return a + (b - a) * (fa / std::max(fa - fb, 1e-12));
}

}  // namespace ts::preview
