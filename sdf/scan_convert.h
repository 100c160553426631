#pragma once
// GPU scan conversion of a triangle mesh into a narrow-band signed distance field (thesis 6.2 and
// 6.2.1, after Erleben & Dohlmann 2006). The grid is processed in z-slabs so GPU memory is bounded by
// the slab, not the box; each slab is read back as it finishes and its band voxels go into an
// OpenVDB level set. See docs/architecture.md, "sdf".
#include <openvdb/openvdb.h>

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "gpu/context.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/sdf_texture.h"

namespace ts::sdf {

struct ScanConvertOptions {
  double band = 3.0;                         // half-width of the narrow band [voxels]
  std::size_t max_slab_bytes = 1ull << 30;   // GPU render-target budget per slab [bytes]
  bool timings = false;                      // per-kernel GPU timer queries
  bool keep_dense = false;                   // also return the whole grid densely on the host (tests, preview)
  // Also leave the whole grid in a GPU 3D texture (the sampler, in the same process): filled slab by
  // slab on the GPU; only a 1-bit-per-voxel inside mask from the CPU flood fill is uploaded.
  bool keep_texture = false;
  bool build_grid = true;                    // the OpenVDB level set (needs voxel_size >= kMinVdbVoxelSize)
  std::function<void(double fraction_done)> progress;  // called after each slab
};

struct ScanConvertStats {
  int slabs = 0;
  int layers_per_slab = 0;
  int draws = 0;
  std::size_t peak_gpu_bytes = 0;      // render targets + geometry buffers (+ texture and mask if keep_texture)
  std::size_t band_voxels = 0;         // voxels with |d| < band written to the grid
  std::size_t degenerate_triangles = 0;  // zero area: skipped, their edges belong to their neighbours
  std::size_t needle_triangles = 0;      // slivers bounded by an in-plane rectangle instead of a miter
  double seconds = 0.0;
  std::string timing_report;           // filled when options.timings
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
  SdfTexture texture;            // only when options.keep_texture: the same values as `dense`, on the GPU
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
