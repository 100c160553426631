#pragma once
// The field the preview ray-casts: a dense narrow-band SDF in voxel units, from the sdf stage's
// dense copy (a mesh scan-converted in-process) or from a level-set .vdb file (densified). The
// renderer uploads it as a 3D texture with hardware trilinear filtering.
#include <openvdb/openvdb.h>

#include <filesystem>
#include <vector>

#include "core/mesh.h"
#include "gpu/context.h"
#include "sdf/grid.h"
#include "sdf/scan_convert.h"
#include "sdf/settings.h"

namespace ts::preview {

struct SdfVolume {
  sdf::GridSpec spec;            // voxel (i, j, k) centre at spec.voxel_center(i, j, k) [m]
  double band = 3.0;             // half-width of the narrow band [voxels]; |distance| saturates there
  std::vector<float> distance;   // signed distance [voxels], spec.linear_index order, clamped to +-band

  bool empty() const { return distance.empty(); }
  Aabb world_box() const;        // the voxel centres' box [m]
};

// From the sdf stage's dense copy (w: signed distance in metres).
SdfVolume volume_from_dense(const sdf::DenseSdf& dense, double band_voxels);

// From the first float level set of a .vdb file: its active voxels' box, padded by two voxels,
// densified (tiles and the flood-filled inside included). ts::InputError naming `file` for a
// transform that is not a uniform scale plus translation, a background of zero, a side above
// max_side voxels (the GPU's 3D texture limit; 0: none) or more than max_voxels in all, checked
// before any memory is spent.
SdfVolume volume_from_level_set(const openvdb::FloatGrid& grid, const std::filesystem::path& file, int max_side = 0,
                                std::size_t max_voxels = std::size_t{1} << 31);

// Scan-converts a mesh on the GPU (sdf::scan_convert with a dense copy) on make_grid(settings).
SdfVolume volume_from_mesh(gpu::Context& context, const TriangleMesh& mesh, const sdf::SdfSettings& settings);

}  // namespace ts::preview
