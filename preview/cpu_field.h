#pragma once
// The SDF as the CPU renderer (preview/cpu_renderer.h) reads it: the preview's OpenVDB level set
// (SdfVolume::level_set) in voxel coordinates of its grid spec (voxel centres at integers, as
// shaders/preview/volume.glsl reads the NanoVDB copy), trilinear and clamped to the band like the GL
// ray cast, with OpenVDB's level-set ray intersector (openvdb/tools/RayIntersector.h) finding the
// first zero crossing along a ray: its HDDA skips empty nodes and tiles, then it steps voxel by
// voxel through the band and refines the crossing on the trilinear field.
#include <openvdb/openvdb.h>
#include <openvdb/tools/RayIntersector.h>

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "preview/volume.h"

namespace ts::preview {

class CpuField {
  // Four secant steps refine each crossing, as the GL ray cast's regula falsi does.
  using Intersector =
      openvdb::tools::LevelSetRayIntersector<openvdb::FloatGrid, openvdb::tools::LinearSearchImpl<openvdb::FloatGrid, 4>>;

 public:
  // ts::InputError (as the GL renderer's set_volume) for an empty field or one under 2 voxels a side.
  explicit CpuField(const SdfVolume& volume);

  const sdf::GridSpec& spec() const { return spec_; }
  double band() const { return band_; }  // [voxels]

  // Voxel coordinates of a world point (the spec's voxel (0, 0, 0) at 0) and back [m].
  Eigen::Vector3d to_voxel(const Eigen::Vector3d& world) const;

  // One thread's view of the field: OpenVDB's accessors and intersector cache the last nodes they
  // visited, so each thread (each tile of pixels) takes its own.
  class Reader {
   public:
    explicit Reader(const CpuField& field);
    // Signed distance [voxels] at voxel coordinates u, trilinear between voxel centres, clamped to
    // the band (volume.glsl's sdf_at).
    double sdf_at(const Eigen::Vector3d& u);
    // Unit outward normal by central differences one voxel apart (volume.glsl's sdf_normal).
    Eigen::Vector3d normal(const Eigen::Vector3d& u);
    // How closed in a surface point is, 0 open .. 1: shade.frag's surface_occlusion sum, before its
    // gain (shaders/preview/look.h) turns it into the ambient factor.
    double occlusion(const Eigen::Vector3d& u, const Eigen::Vector3d& n);
    // The first zero crossing of the ray o + t dir (voxel units, unit dir) within [t0, t1], by the
    // level-set ray intersector; nullopt when there is none.
    std::optional<double> first_crossing(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, double t0, double t1);

   private:
    // The crossing in [a, b] (f(a) > 0 >= f(b)) by raycast.frag's regula falsi on the clamped
    // trilinear field; nullopt when [a, b] does not bracket one.
    std::optional<double> refine(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, double a, double b);

    const CpuField& field_;
    openvdb::FloatGrid::ConstAccessor accessor_;
    Intersector intersector_;
  };

 private:
  sdf::GridSpec spec_;
  double band_ = 0.0;
  // The level set sharing SdfVolume's tree, its transform of the spec's voxel size, so the
  // intersector's band test (two voxels of distance) reads world-unit values in world units.
  openvdb::FloatGrid::Ptr grid_;
  // The first intersector, copied by each Reader (its construction walks the tree's bounding box).
  std::shared_ptr<const Intersector> intersector_;
};

}  // namespace ts::preview
