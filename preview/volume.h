#pragma once
// The field the preview ray-casts: the narrow-band SDF as a sparse NanoVDB level set on the host,
// from a mesh scan-converted in-process or from a level-set .vdb file, never densified. The renderer
// uploads it as one storage buffer (sdf::SparseField) and marches it with NanoVDB's HDDA, which
// skips the empty space between the band's leaves.
#include <openvdb/openvdb.h>

#include <filesystem>

#include "core/mesh.h"
#include "gpu/context.h"
#include "sdf/grid.h"
#include "sdf/settings.h"
#include "sdf/sparse_field.h"

namespace ts::preview {

struct SdfVolume {
  sdf::GridSpec spec;   // the box of the band; voxel (i, j, k) at NanoVDB index spec.index_offset + (i, j, k)
  double band = 3.0;    // half-width of the narrow band [voxels]; |distance| saturates there
  sdf::NanoGrid grid;   // signed distance [m] in the band, +-band * voxel off it (the GL renderer's)
  // The same level set as OpenVDB holds it, shared, not copied (the CPU renderer's): index (i, j, k) of
  // the grid at spec.index_offset + (i, j, k), values in world units; its transform is not used.
  openvdb::FloatGrid::ConstPtr level_set;
  Aabb surface;         // the voxels at or inside the zero level, grown by half a voxel [m]
  std::size_t band_voxels = 0;  // active voxels of the level set

  bool empty() const { return !grid.grid<float>(); }
  Aabb world_box() const;       // the voxel centres' box [m]
  // Whether the field reads inside at its box's corner, which lies outside every solid (the box pads
  // the surface by at least two voxels): signs that flood the whole box, as pseudonormals do through
  // the holes of an open mesh. Ray-cast, such a field is a solid box, not the surface.
  bool inside_out() const;
};

// From the first float level set of a .vdb file: its active voxels' box, padded by two voxels.
// ts::InputError naming `file` for a transform that is not a uniform scale plus translation or a
// background of zero. Memory follows the band: the box may be any size.
SdfVolume volume_from_level_set(const openvdb::FloatGrid& grid, const std::filesystem::path& file);

// Scan-converts a mesh on the GPU (sdf::scan_convert into an index-space level set) on make_grid(settings);
// settings.sign Winding re-signs it by the generalised winding number (sdf::resign_by_winding_number), the
// signs of an open mesh.
SdfVolume volume_from_mesh(gpu::Context& context, const TriangleMesh& mesh, const sdf::SdfSettings& settings);
// The same grid without a GL context: the exact SDF on every core (sdf::exact_sdf_grid, signed by
// settings.sign, as the scan conversion's), for the CPU renderer.
SdfVolume volume_from_mesh_on_cpu(const TriangleMesh& mesh, const sdf::SdfSettings& settings);

}  // namespace ts::preview
