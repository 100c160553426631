#pragma once
// The compute-shader scan conversion of one z-slab (ScanMethod::Compute in sdf/scan_convert.h), after
// the triangle/leaf pairs of NanoVDB's CUDA mesh-to-grid: every usable triangle is paired with the
// brick^3 voxel bricks its band can reach (made on the GPU by counts, prefix sums and a scatter,
// grouped by brick row). Per slab the pairs become a triangle list per brick (count, prefix sum,
// scatter), and one work group per brick takes, per voxel, the least distance to the brick's triangles
// and at equal distance the least triangle index (never the list's order, which atomics decide), and
// stores that triangle's value into the same slab target the geometry path draws into. Everything
// downstream (band compaction, read-back, outputs) is shared. Compute shaders run on every core of a
// GPU, where geometry and fragment stages run on a few (docs/architecture.md, "sdf").
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "gpu/gl.h"
#include "gpu/graphics.h"
#include "gpu/hash_grid.h"
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
// bricks of its bounding box grown by the margin whose centre lies within margin + (brick - 1) / 2 *
// |n|_1 of its plane and within margin + (brick - 1) / 2 * sqrt(3) of it (float, the GPU's arithmetic).
// Grouped by brick row (brick z).
struct BrickPairs {
  int brick = 4;                         // the side of a brick [voxels]
  std::vector<std::uint32_t> words;      // 2 per pair: triangle index, brick x | brick y << 16
  std::vector<std::uint32_t> row_begin;  // per brick row, its first pair; one more entry: the pair count
  std::size_t count() const { return words.size() / 2; }
};

// The host's pairs, triangles ascending within each row: the reference the GPU's pairs are tested
// against (the scan conversion makes its pairs on the GPU, BrickPairGenerator). `triangles` in
// grid-local voxel units (face_normal.xyz the unit normal, w 0 for a degenerate triangle); `usable`:
// the indices to pair. GpuError as BrickPairGenerator::run.
BrickPairs build_brick_pairs(std::span<const gpu::layout::SdfTriangle> triangles,
                             std::span<const std::uint32_t> usable, const GridSpec& spec, double margin,
                             int brick);

// The pairs on the GPU: uvec2 per pair (as BrickPairs::words), grouped by brick row, in no fixed order
// within a row; the rows' first pairs on the host (all that came back).
struct GpuBrickPairs {
  int brick = 4;
  gpu::Buffer pairs;
  std::vector<std::uint32_t> row_begin;  // per brick row, its first pair; one more entry: the pair count
  std::size_t count() const { return row_begin.empty() ? 0 : row_begin.back(); }
  std::size_t bytes() const { return pairs.bytes() + row_begin.size() * sizeof(std::uint32_t); }
  // The pairs read back (tests and diagnostics only: the scan conversion never reads them).
  BrickPairs download() const;
};

// Makes the pairs on the GPU (shaders/sdf/brick_pairs.comp): per triangle its brick rows, their
// prefix sum, per triangle row the bricks reached (atomic row totals), the row starts (the host's
// prefix sum of the row totals, the one read-back), and the scatter.
class BrickPairGenerator {
 public:
  explicit BrickPairGenerator(const gpu::ShaderLibrary& library);
  // `triangles`: SdfTriangle[count], grid-local voxel units; degenerate ones (face_normal.w == 0) get
  // no pairs. GpuError when the grid has more bricks along x or y than 16 bits number or more pairs
  // than 32 bits do.
  GpuBrickPairs run(gpu::Queue& queue, const gpu::Buffer& triangles, std::uint32_t count, const GridSpec& spec,
                    double margin, int brick);

 private:
  gpu::Program spans_, count_, scatter_;
  gpu::PrefixScan scan_;
  gpu::ParamBlock<gpu::params::BrickPairParams> params_;
};

// GPU memory the compute path adds per slab voxel at most: one word per brick of the slab (its first
// triangle), a brick being at least 2^3 voxels, rounded up to a word a voxel for the brick rows a slab
// shares with its neighbours. The slab's pair lists (8 bytes a pair) come on top, bounded by the pairs.
inline constexpr std::size_t kComputeScanBytesPerVoxel = sizeof(std::uint32_t);

// The compute kernels, the pairs on the GPU and the per-slab brick lists (shaders/sdf/scan_bricks.comp).
class ComputeScan {
 public:
  ComputeScan(const gpu::ShaderLibrary& library, GpuBrickPairs pairs, const GridSpec& spec, int slab_layers,
              double band);
  // Writes the value of every voxel of grid layers [z0, z0 + layers) with a triangle closer than the
  // band into layers [0, layers) of `target` (RGBA32F, already cleared to the untouched value);
  // `triangles`: SdfTriangle[], those the pairs were made from. Returns the pairs it ran.
  std::size_t fill(gpu::Queue& queue, const gpu::Buffer& triangles, const gpu::Texture& target, int z0,
                   int layers);
  std::size_t gpu_bytes() const {
    return pairs_.bytes() + rows_.bytes() + brick_starts_.bytes() + pair_slots_.bytes() + brick_triangles_.bytes();
  }

 private:
  // Grows the per-slab buffers to `bricks` brick starts (+1) and `pairs` slots and list entries.
  void reserve(std::size_t bricks, std::size_t pairs);

  GridSpec spec_;
  float band_;
  int brick_;
  std::vector<std::uint32_t> row_begin_;
  gpu::Program count_pass_, scatter_pass_, brick_pass_;
  gpu::PrefixScan scan_;
  gpu::Buffer pairs_, rows_, brick_starts_, pair_slots_, brick_triangles_;
  gpu::ParamBlock<gpu::params::ComputeScanParams> params_;
};

}  // namespace ts::sdf
