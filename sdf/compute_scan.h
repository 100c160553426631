#pragma once
// The compute-shader scan conversion of one z-slab (ScanMethod::Compute in sdf/scan_convert.h), after
// the triangle/leaf pairs of NanoVDB's CUDA mesh-to-grid: every usable triangle is paired with the
// brick^3 voxel bricks its band can reach (host side, sorted by brick row); per slab one work
// group per pair finds, per voxel, the least distance to any triangle (atomic minimum on the distance
// bits), a second pass the least triangle index at that distance (ties never depend on arrival order),
// and a per-voxel pass stores that triangle's value into the same slab target the geometry path draws
// into. Everything downstream (band compaction, read-back, outputs) is shared. Compute shaders run on
// every core of a GPU, where geometry and fragment stages run on a few (docs/architecture.md, "sdf").
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "gpu/gl.h"
#include "gpu/graphics.h"
#include "gpu/layouts.h"
#include "gpu/params.h"
#include "gpu/shader_library.h"
#include "sdf/grid.h"

namespace ts::sdf {

// The side of a brick [voxels]: 2 on a software renderer, where a work group of 8 is one SIMD batch
// and a 4^3 brick spent most of its invocations on voxels beyond the band (fandisk at 40 on llvmpipe:
// 1.7x the geometry path's time with 4^3, about 1.0x with 2^3); 4 on a GPU, whose SIMD groups are
// 32 or 64 invocations wide (not measured on one yet).
int compute_brick_side(bool software_renderer);

// Every usable triangle with each voxel brick whose voxel centres may lie within `margin` of it: the
// bricks of its bounding box grown by the margin whose centre box meets the slab of its plane grown by
// the margin. Sorted by brick row (brick z), triangles ascending within a row.
struct BrickPairs {
  int brick = 4;                         // the side of a brick [voxels]
  std::vector<std::uint32_t> words;      // 2 per pair: triangle index, brick x | brick y << 16
  std::vector<std::uint32_t> row_begin;  // per brick row, its first pair; one more entry: the pair count
  std::size_t count() const { return words.size() / 2; }
};

// `triangles` in grid-local voxel units (face_normal.xyz the unit normal); `usable`: the indices to
// pair (the non-degenerate ones). GpuError when the grid has more bricks along x or y than 16 bits
// number or more pairs than 32 bits do.
BrickPairs build_brick_pairs(std::span<const gpu::layout::SdfTriangle> triangles,
                             std::span<const std::uint32_t> usable, const GridSpec& spec, double margin,
                             int brick);

// GPU memory the compute path adds per slab voxel: the nearest distance and nearest triangle words.
inline constexpr std::size_t kComputeScanBytesPerVoxel = 2 * sizeof(std::uint32_t);

// The compute kernels, the pairs on the GPU and the per-voxel minimum buffers of one slab target.
class ComputeScan {
 public:
  ComputeScan(const gpu::ShaderLibrary& library, const BrickPairs& pairs, const GridSpec& spec,
              int slab_layers, double band);
  // Writes the value of every voxel of grid layers [z0, z0 + layers) with a triangle closer than the
  // band into layers [0, layers) of `target` (RGBA32F, already cleared to the untouched value);
  // `triangles` (SdfTriangle[]) must be bound at TS_SDF_TRIANGLES. Returns the pairs it ran.
  std::size_t fill(gpu::Queue& queue, const gpu::Texture& target, int z0, int layers);
  std::size_t gpu_bytes() const {
    return pairs_.bytes() + rows_.bytes() + nearest_distance_.bytes() + nearest_triangle_.bytes();
  }

 private:
  GridSpec spec_;
  float band_;
  int brick_;
  std::vector<std::uint32_t> row_begin_;
  gpu::Program nearest_distance_pass_, nearest_triangle_pass_, write_pass_;
  gpu::Buffer pairs_, rows_, nearest_distance_, nearest_triangle_;
  gpu::ParamBlock<gpu::params::ComputeScanParams> params_;
};

}  // namespace ts::sdf
