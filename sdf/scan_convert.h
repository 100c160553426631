#pragma once
// GPU scan conversion of a triangle mesh into a narrow-band signed distance field (thesis 6.2 and
// 6.2.1, after Erleben & Dohlmann 2006). The grid is processed in z-slabs so GPU memory is bounded by
// the slab, not the box; as each slab finishes its band voxels are compacted on the GPU (a prefix sum
// over band flags) and only they are read back, into an OpenVDB level set, so host traffic and host
// memory follow the band too. See docs/architecture.md, "sdf".
#include <openvdb/openvdb.h>

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "gpu/context.h"
#include "sdf/grid.h"
#include "sdf/leaf_field.h"
#include "sdf/pseudonormals.h"
#include "sdf/settings.h"

namespace ts::sdf {

struct ScanConvertOptions {
  ScanMethod method = ScanMethod::Geometry;
  int compute_brick = 0;  // compute path: brick side [voxels], 2 or 4; 0: compute_brick_side for the device
  double band = 3.0;                         // half-width of the narrow band [voxels]
  std::size_t max_slab_bytes = 1ull << 30;   // GPU render-target budget per slab [bytes]
  bool timings = false;                      // per-kernel GPU timer queries
  // Geometry path: count what the raster pipeline did (gpu::PipelineStatistics, where the device has the
  // queries) against the prism model (sdf/prism_model.h). A host wait per slab.
  bool pipeline_statistics = false;
  bool keep_dense = false;                   // also return the whole grid densely on the host (tests)
  bool build_grid = true;                    // the OpenVDB level set
  // The level set's transform: world units (voxel_size, for .vdb files; needs voxel_size >=
  // kMinVdbVoxelSize), or index space (voxel size 1, values still in world units: any voxel size,
  // for a GPU field built in the same process, sdf::SparseField).
  bool index_space_grid = false;
  // The field as the GPU's kernels read it, built and kept on the GPU from each filled slab
  // (sdf::LeafField): nothing of it is read back. With build_grid and keep_dense false the band is
  // not read back at all. Slabs then hold a multiple of 8 layers.
  bool gpu_field = false;
  std::size_t gpu_field_slots = 0;  // leaf slots to allocate; 0: band_leaf_bound of the mesh

  std::function<void(double fraction_done)> progress;  // called after each slab
};

// The geometry path's pipeline statistics beside the prism model's figures (options.pipeline_statistics).
struct ScanPipelineWork {
  bool measured = false;                    // false: not asked for, the compute path, or no queries
  std::uint64_t geometry_invocations = 0;   // geometry-shader invocations (instances count one each)
  std::uint64_t geometry_primitives = 0;    // primitives the geometry shader emitted
  std::uint64_t fragments = 0;              // fragment-shader invocations (llvmpipe: 16 per 4x4 block shaded)
  std::uint64_t drawn_prisms = 0;           // input primitives over all draws (llvmpipe counts these as invocations)
  std::uint64_t model_invocations = 0;      // prisms per draw x the draw's variant's invocations
  std::uint64_t model_primitives = 0;       // cross-sections by the shader's slicing rules
  double model_volume = 0.0;                // summed prism volume [voxels^3]: voxel centres inside
};

struct ScanConvertStats {
  int slabs = 0;
  int layers_per_slab = 0;
  ScanMethod method = ScanMethod::Geometry;
  int draws = 0;                       // geometry path: draw calls
  std::size_t brick_pairs = 0;         // compute path: triangle/brick pairs (sdf/compute_scan.h)
  std::size_t peak_gpu_bytes = 0;      // render target, geometry and band-compaction buffers
  std::size_t band_voxels = 0;         // voxels with |d| < band written to the grid
  std::size_t readback_bytes = 0;      // field bytes GPU -> host: the compacted band (20 bytes a voxel) when
                                       // a host output asks for it; the counts read besides are not counted
  std::size_t degenerate_triangles = 0;  // zero area: skipped, their edges belong to their neighbours
  std::size_t needle_triangles = 0;      // slivers bounded by an in-plane rectangle instead of a miter
  double seconds = 0.0;                  // the whole call
  // Where the time went (seconds, host wall clock; planning and setup make up the rest of `seconds`):
  double gpu_seconds = 0.0;         // draws and band compaction, the host issuing them and waiting for them
  double readback_seconds = 0.0;    // the band's download (from the wait for the last compaction kernel on)
  double host_build_seconds = 0.0;  // the outputs on the caller's thread: copying each band, waiting for
                                    // the level set's leaves, the signed flood fill
  double leaf_build_seconds = 0.0;  // the level set's leaves built and linked, mostly beside the GPU's work
  std::string timing_report;           // filled when options.timings
  ScanPipelineWork pipeline;           // filled when options.pipeline_statistics, geometry path
};

// A dense copy of the field: per voxel, xyz = unit gradient, w = signed distance [world units].
// Voxels outside the band hold +-band with the sign of a flood fill and a zero gradient.
struct DenseSdf {
  GridSpec spec;
  std::vector<Eigen::Vector4f> values;  // spec.linear_index(i, j, k)
};

struct ScanConvertResult {
  openvdb::FloatGrid::Ptr grid;  // level set in world units, background = band * voxel_size (if build_grid)
  ScanConvertStats stats;
  DenseSdf dense;                // only when options.keep_dense
  std::optional<LeafField> field;  // only when options.gpu_field
};

// Requires a current context (gpu::Context). Throws GpuError when the GPU cannot hold one layer.
ScanConvertResult scan_convert(gpu::Context& context, const TriangleMesh& mesh, const Pseudonormals& normals,
                               const GridSpec& spec, const ScanConvertOptions& options);

// OpenVDB refuses linear transforms whose determinant (voxel_size^3) it deems zero: below this voxel
// size a level set cannot be stored in world units (express the mesh in smaller units instead).
inline constexpr double kMinVdbVoxelSize = 1.3e-5;

// Bytes of GPU render target one z-layer of `spec` needs (colour RGBA32F + depth 32F).
std::size_t bytes_per_layer(const GridSpec& spec);

}  // namespace ts::sdf
