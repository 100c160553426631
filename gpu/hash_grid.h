#pragma once
// A hashed uniform grid rebuilt on the GPU by counting sort: count per cell, exclusive prefix sum,
// scatter, and an in-cell sort by particle id for deterministic neighbour order. Memory follows the
// particle count (hash table = next power of two >= 2 x particles), never the domain size.
//
// Bindings the neighbour kernels read after build(): TS_GRID_CELL_COUNT, TS_GRID_CELL_START and
// TS_GRID_SORTED (shaders/common/bindings.h; the hash is in shaders/common/hash_grid.glsl).
#include <cstdint>

#include "gpu/gl.h"
#include "gpu/params.h"

namespace ts::gpu {

// Exclusive prefix sum of uint buffers, recursive over 512-value blocks.
class PrefixScan {
 public:
  explicit PrefixScan(const ShaderLibrary& library);
  // Scans values[0, count) in place.
  void run(Queue& queue, Buffer& values, std::uint32_t count);

 private:
  Program blocks_, add_;
  ParamBlock<params::ItemCount> params_;  // values in the level a kernel runs on
  std::vector<Buffer> levels_;  // levels_[l]: block sums of level l (level 0 = the values), grown on demand
};

// Counting sort of `count` ids by keys below `table_size`, finished here once a key kernel has
// written each id's key (`keys`, TS_SORT_KEY), its bucket's size (`counts`, TS_SORT_BUCKET_COUNT,
// zeroed before) and its slot in the bucket (`slots`, TS_SORT_SLOT): bucket starts by exclusive scan
// (`starts`, TS_SORT_BUCKET_START), ids scattered to start + slot (`sorted`, TS_SORT_SORTED), then
// sorted within each bucket, so the order does not depend on the
// atomics that handed out the slots. Shared by the hash grid and the simulator's Morton re-sort.
class BucketSort {
 public:
  explicit BucketSort(const ShaderLibrary& library);
  void finish(Queue& queue, const Buffer& keys, const Buffer& counts, const Buffer& slots, Buffer& starts,
              Buffer& sorted, std::uint32_t count, std::uint32_t table_size);

 private:
  Program scatter_, sort_buckets_, copy_;
  ParamBlock<params::GridParams> params_;  // ids and buckets (scatter and in-bucket sort alike)
  ParamBlock<params::ItemCount> copy_params_;
  PrefixScan scan_;
};

class HashGrid {
 public:
  explicit HashGrid(const ShaderLibrary& library);
  // positions: vec4 per particle (xyz used), bound to TS_GRID_POSITIONS during the build. Every
  // step of the build is a kernel (the clear and the copy too), so the whole build can be GPU-decided
  // work (Queue::begin_indirect).
  void build(Queue& queue, const Buffer& positions, std::uint32_t count, float cell_size);
  // Rebinds the grid to TS_GRID_CELL_COUNT, TS_GRID_CELL_START and TS_GRID_SORTED for a neighbour kernel.
  void bind() const;
  std::uint32_t table_size() const { return table_size_; }
  float cell_size() const { return cell_size_; }
  std::size_t bytes() const;

 private:
  void reserve(std::uint32_t count);
  Program count_, zero_;
  ParamBlock<params::GridParams> params_;
  ParamBlock<params::ItemCount> zero_params_;
  BucketSort sort_;
  Buffer cell_of_, slot_, cell_count_, cell_start_, sorted_;
  std::uint32_t capacity_ = 0, table_size_ = 0;
  float cell_size_ = 0.0f;
};

}  // namespace ts::gpu
