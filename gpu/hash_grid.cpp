#include "gpu/hash_grid.h"

#include <bit>

#include "shaders/common/bindings.h"

namespace ts::gpu {

PrefixScan::PrefixScan(const ShaderLibrary& library)
    : blocks_(Program::compute(library, "common/scan_blocks.comp")),
      add_(Program::compute(library, "common/scan_add.comp")) {}

void PrefixScan::run(Queue& queue, Buffer& values, std::uint32_t count) {
  // Level l+1 holds the block sums of level l; the last level is a single block's total.
  std::vector<std::uint32_t> sizes{count};
  while (sizes.back() > 512u) sizes.push_back((sizes.back() + 511u) / 512u);
  if (levels_.size() < sizes.size()) levels_.resize(sizes.size());  // before any address is taken
  for (std::size_t l = 1; l <= sizes.size(); ++l) {
    const std::size_t bytes = (l < sizes.size() ? sizes[l] : 1u) * sizeof(std::uint32_t);
    if (levels_[l - 1].bytes() < bytes) levels_[l - 1] = Buffer(bytes);
  }
  auto level_buffer = [&](std::size_t l) -> Buffer& { return l == 0 ? values : levels_[l - 1]; };
  // Down: scan each level's blocks, writing block sums to the next level.
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    level_buffer(l).bind(TS_SCAN_VALUES);
    level_buffer(l + 1).bind(TS_SCAN_BLOCK_SUMS);
    params_.values.count.x = sizes[l];
    params_.bind(TS_SCAN_PARAMS);
    queue.dispatch_groups(blocks_, (sizes[l] + 511u) / 512u);
  }
  // Up: add each level's scanned block offsets back into the level below.
  for (std::size_t l = sizes.size() - 1; l-- > 0;) {
    level_buffer(l).bind(TS_SCAN_VALUES);
    level_buffer(l + 1).bind(TS_SCAN_BLOCK_SUMS);
    params_.values.count.x = sizes[l];
    params_.bind(TS_SCAN_PARAMS);
    queue.dispatch_items(add_, sizes[l]);
  }
}

BucketSort::BucketSort(const ShaderLibrary& library)
    : scatter_(Program::compute(library, "common/grid_scatter.comp")),
      sort_buckets_(Program::compute(library, "common/grid_sort_cells.comp")),
      copy_(Program::compute(library, "common/copy_uints.comp")),
      scan_(library) {}

void BucketSort::finish(Queue& queue, const Buffer& keys, const Buffer& counts, const Buffer& slots, Buffer& starts,
                        Buffer& sorted, std::uint32_t count, std::uint32_t table_size) {
  counts.bind(TS_COPY_SOURCE);
  starts.bind(TS_COPY_DESTINATION);
  copy_params_.values.count.x = table_size;
  copy_params_.bind(TS_FILL_PARAMS);
  queue.dispatch_items(copy_, table_size);
  scan_.run(queue, starts, table_size);
  keys.bind(TS_SORT_KEY);
  counts.bind(TS_SORT_BUCKET_COUNT);
  slots.bind(TS_SORT_SLOT);
  starts.bind(TS_SORT_BUCKET_START);
  sorted.bind(TS_SORT_SORTED);
  params_.values.sizes = {count, table_size, 0u, 0u};
  params_.bind(TS_GRID_PARAMS);
  queue.dispatch_items(scatter_, count);
  queue.dispatch_items(sort_buckets_, table_size);
}

HashGrid::HashGrid(const ShaderLibrary& library)
    : count_(Program::compute(library, "common/grid_count.comp")),
      zero_(Program::compute(library, "common/zero_uints.comp")),
      sort_(library) {}

void HashGrid::reserve(std::uint32_t count) {
  if (count <= capacity_ && table_size_ != 0) return;
  capacity_ = std::max<std::uint32_t>(count, 64u);
  table_size_ = std::bit_ceil(2u * capacity_);
  const std::size_t ids = capacity_ * sizeof(std::uint32_t), cells = table_size_ * sizeof(std::uint32_t);
  cell_of_ = Buffer(ids);
  slot_ = Buffer(ids);
  sorted_ = Buffer(ids);
  cell_count_ = Buffer(cells);
  cell_start_ = Buffer(cells);
}

void HashGrid::build(Queue& queue, const Buffer& positions, std::uint32_t count, float cell_size) {
  reserve(count);
  cell_size_ = cell_size;
  cell_count_.bind(TS_FILL_VALUES);
  zero_params_.values.count.x = table_size_;
  zero_params_.bind(TS_FILL_PARAMS);
  queue.dispatch_items(zero_, table_size_);
  positions.bind(TS_GRID_POSITIONS);
  cell_of_.bind(TS_SORT_KEY);
  cell_count_.bind(TS_SORT_BUCKET_COUNT);
  slot_.bind(TS_SORT_SLOT);
  params_.values.sizes = {count, table_size_, 0u, 0u};
  params_.values.cell.x = cell_size;
  params_.bind(TS_GRID_PARAMS);
  queue.dispatch_items(count_, count);
  sort_.finish(queue, cell_of_, cell_count_, slot_, cell_start_, sorted_, count, table_size_);
}

void HashGrid::bind() const {
  cell_count_.bind(TS_GRID_CELL_COUNT);
  cell_start_.bind(TS_GRID_CELL_START);
  sorted_.bind(TS_GRID_SORTED);
}

std::size_t HashGrid::bytes() const {
  return cell_of_.bytes() + slot_.bytes() + sorted_.bytes() + cell_count_.bytes() + cell_start_.bytes();
}

}  // namespace ts::gpu
