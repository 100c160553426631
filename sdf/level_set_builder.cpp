#include "sdf/level_set_builder.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <span>
#include <vector>

namespace ts::sdf {
namespace {

using Leaf = openvdb::FloatTree::LeafNodeType;
using Clock = std::chrono::steady_clock;
constexpr int kLeafLog2 = Leaf::LOG2DIM;  // 3: a leaf is 8 voxels a side
static_assert(Leaf::DIM == 8, "leaf rows below are 8 voxels deep");

double since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The leaves one slab touches, as rows of leaves along x: leaf blocks [bz0, bz1] along z (global
// index space, as OpenVDB numbers them) by [by0, by1] along y. A row is one task; no two rows share
// a leaf, so their tasks never write the same memory.
struct LeafRows {
  openvdb::Coord offset;  // the grid's index offset
  int nx = 0, ny = 0;
  int z_lo = 0, z_hi = 0;  // the slab's global z range holding band voxels
  int bz0 = 0, by0 = 0, by1 = 0, bx0 = 0, bx1 = 0;
  int rows_y() const { return by1 - by0 + 1; }
  int row_count(int bz1) const { return (bz1 - bz0 + 1) * rows_y(); }
};

// One row of leaves (leaf block bz along z, by along y) filled from the slab's band. Leaves a slab
// before this one began (the row's z block starts below the slab) are in the tree already and are
// filled in place; the others are made here and returned in `created` for linking.
void fill_row(const LeafRows& r, int bz, int by, std::span<const std::size_t> voxels,
              std::span<const float> distances, openvdb::FloatTree& tree, std::vector<Leaf*>& row,
              std::vector<std::unique_ptr<Leaf>>& created) {
  const int z0 = std::max(bz << kLeafLog2, r.z_lo),
            z1 = std::min((bz << kLeafLog2) + static_cast<int>(Leaf::DIM) - 1, r.z_hi);
  const int j0 = std::max((by << kLeafLog2) - r.offset.y(), 0);
  const int j1 = std::min((by << kLeafLog2) + static_cast<int>(Leaf::DIM) - r.offset.y(), r.ny);
  const bool continued = (bz << kLeafLog2) < r.z_lo;
  const std::size_t nx = static_cast<std::size_t>(r.nx), layer = nx * static_cast<std::size_t>(r.ny);
  std::fill(row.begin(), row.end(), nullptr);
  for (int z = z0; z <= z1; ++z) {
    const std::size_t layer_start = static_cast<std::size_t>(z - r.z_lo) * layer;
    // Rows j0..j1-1 of one layer are one run of the ascending band list.
    const auto begin =
        std::lower_bound(voxels.begin(), voxels.end(), layer_start + static_cast<std::size_t>(j0) * nx);
    const auto end = std::lower_bound(begin, voxels.end(), layer_start + static_cast<std::size_t>(j1) * nx);
    // The run ascends, so rows are stepped through, not divided out.
    int j = j0;
    std::size_t row_start = layer_start + static_cast<std::size_t>(j0) * nx;
    for (auto it = begin; it != end; ++it) {
      while (*it >= row_start + nx) ++j, row_start += nx;
      const openvdb::Coord c(r.offset.x() + static_cast<int>(*it - row_start), r.offset.y() + j, z);
      Leaf*& leaf = row[static_cast<std::size_t>((c.x() >> kLeafLog2) - r.bx0)];
      if (!leaf && continued) leaf = tree.probeLeaf(c);
      if (!leaf) {
        created.push_back(std::make_unique<Leaf>(c, tree.background(), false));
        leaf = created.back().get();
      }
      leaf->setValueOn(Leaf::coordToOffset(c), distances[static_cast<std::size_t>(it - voxels.begin())]);
    }
  }
}

}  // namespace

openvdb::Coord band_voxel_coord(const GridSpec& spec, int z0, std::size_t voxel) {
  const std::size_t nx = static_cast<std::size_t>(spec.dims.x());
  const std::size_t layer = nx * static_cast<std::size_t>(spec.dims.y());
  const int i = static_cast<int>(voxel % nx);
  const int j = static_cast<int>((voxel / nx) % static_cast<std::size_t>(spec.dims.y()));
  const int k = z0 + static_cast<int>(voxel / layer);
  return {spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k};
}

void insert_band_serial(openvdb::FloatTree& tree, const GridSpec& spec, float voxel_size,
                        const BandSlab& slab) {
  openvdb::tree::ValueAccessor<openvdb::FloatTree> accessor(tree);
  for (std::size_t k = 0; k < slab.voxels.size(); ++k)
    accessor.setValue(band_voxel_coord(spec, slab.z0, slab.voxels[k]), slab.values[4 * k + 3] * voxel_size);
}

LevelSetBuilder::LevelSetBuilder(openvdb::FloatTree& tree, const GridSpec& spec, float voxel_size,
                                 bool overlapped)
    : tree_(tree), spec_(spec), voxel_size_(voxel_size), overlapped_(overlapped) {}

LevelSetBuilder::~LevelSetBuilder() noexcept {
  // A build in flight writes into the tree: let it end before the tree can go. Its error, if any,
  // is lost with the scan that is being unwound.
  try {
    wait();
  } catch (...) {
  }
}

void LevelSetBuilder::wait() {
  if (!in_flight_) return;
  in_flight_ = false;
  tasks_.wait();
}

void LevelSetBuilder::add(const BandSlab& slab) {
  const auto start = Clock::now();
  wait();  // the last slab's leaves are linked before this one's look for them in the tree
  pending_.z0 = slab.z0;
  pending_.voxels.resize(slab.voxels.size());
  pending_.distances.resize(slab.voxels.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, slab.voxels.size(), 1 << 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k != range.end(); ++k) {
                        pending_.voxels[k] = slab.voxels[k];
                        pending_.distances[k] = slab.values[4 * k + 3] * voxel_size_;
                      }
                    });
  if (overlapped_) {
    in_flight_ = true;
    tasks_.run([this] { build(pending_); });
  } else {
    build(pending_);
  }
  caller_seconds_ += since(start);
}

void LevelSetBuilder::finish() {
  const auto start = Clock::now();
  wait();
  caller_seconds_ += since(start);
}

void LevelSetBuilder::build(const Pending& slab) {
  if (slab.voxels.empty()) return;
  const auto start = Clock::now();
  LeafRows r;
  r.offset = openvdb::Coord(spec_.index_offset.x(), spec_.index_offset.y(), spec_.index_offset.z());
  r.nx = spec_.dims.x(), r.ny = spec_.dims.y();
  const std::size_t layer = static_cast<std::size_t>(r.nx) * static_cast<std::size_t>(r.ny);
  r.z_lo = r.offset.z() + slab.z0;
  r.z_hi = r.z_lo + static_cast<int>(slab.voxels.back() / layer);
  r.bz0 = r.z_lo >> kLeafLog2;
  r.by0 = r.offset.y() >> kLeafLog2, r.by1 = (r.offset.y() + r.ny - 1) >> kLeafLog2;
  r.bx0 = r.offset.x() >> kLeafLog2, r.bx1 = (r.offset.x() + r.nx - 1) >> kLeafLog2;
  const int rows = r.row_count(r.z_hi >> kLeafLog2);
  std::vector<std::vector<std::unique_ptr<Leaf>>> created(static_cast<std::size_t>(rows));
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& range) {
    std::vector<Leaf*> row(static_cast<std::size_t>(r.bx1 - r.bx0 + 1));
    for (int n = range.begin(); n != range.end(); ++n) {
      fill_row(r, r.bz0 + n / r.rows_y(), r.by0 + n % r.rows_y(), slab.voxels, slab.distances, tree_, row,
               created[static_cast<std::size_t>(n)]);
    }
  });
  // Linking is serial (the tree's internal nodes are shared) but costs one descent a leaf.
  openvdb::tree::ValueAccessor<openvdb::FloatTree> accessor(tree_);
  for (auto& leaves : created)
    for (auto& leaf : leaves) accessor.addLeaf(leaf.release());
  build_seconds_ += since(start);
}

}  // namespace ts::sdf
