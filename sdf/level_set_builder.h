#pragma once
// The host's share of scan conversion: the band voxels read back slab by slab, turned into the
// OpenVDB level set's tree. Leaves (8^3 voxels) are filled in parallel (TBB), one task per row of
// leaves, and linked into the tree with addLeaf, serially but once a leaf; the build of one slab
// runs in the background while the GPU scans the next (docs/architecture.md, "sdf"). The result is
// the tree one accessor inserting every voxel in order would build (insert_band_serial, kept as the
// reference the tests and bench/sdf_host_build_bench.cpp compare with).
#include <openvdb/openvdb.h>
#include <tbb/task_group.h>

#include <cstddef>
#include <span>
#include <vector>

#include "sdf/grid.h"

namespace ts::sdf {

// One finished slab's band as read back: grid layers from z0 on, the band voxels' slab indices
// (x fastest, then y, then layer; ascending) and 4 floats each (unit gradient, signed distance in
// voxels).
struct BandSlab {
  int z0 = 0;
  std::span<const std::size_t> voxels;
  std::span<const float> values;
};

// Where a band voxel goes in the tree: the index-space coordinate of slab index `voxel`.
openvdb::Coord band_voxel_coord(const GridSpec& spec, int z0, std::size_t voxel);

// The reference: every voxel through one accessor on one thread, distance times voxel_size.
void insert_band_serial(openvdb::FloatTree& tree, const GridSpec& spec, float voxel_size,
                        const BandSlab& slab);

class LevelSetBuilder {
 public:
  // Builds into `tree` (empty, its background the level set's). Overlapped: add() returns once the
  // slab is copied and builds its leaves in the background (the next add() or finish() waits for
  // them); otherwise add() builds them before it returns.
  LevelSetBuilder(openvdb::FloatTree& tree, const GridSpec& spec, float voxel_size, bool overlapped = true);
  ~LevelSetBuilder() noexcept;  // waits for a build in flight (its leaves are freed with the tree)
  LevelSetBuilder(const LevelSetBuilder&) = delete;
  LevelSetBuilder& operator=(const LevelSetBuilder&) = delete;

  // Slabs in ascending z order, each starting where the last ended. The spans may be reused by the
  // caller as soon as add() returns.
  void add(const BandSlab& slab);
  // Waits for the last slab's leaves; the tree then holds every band voxel.
  void finish();

  // Seconds the caller spent in add() and finish() (copying, waiting for builds) and seconds the
  // builds themselves took (on other threads when overlapped).
  double caller_seconds() const { return caller_seconds_; }
  double build_seconds() const { return build_seconds_; }

 private:
  struct Pending {
    int z0 = 0;
    std::vector<std::size_t> voxels;
    std::vector<float> distances;  // world units
  };
  void wait();
  void build(const Pending& slab);

  openvdb::FloatTree& tree_;
  GridSpec spec_;
  float voxel_size_;
  bool overlapped_;
  Pending pending_;
  tbb::task_group tasks_;
  bool in_flight_ = false;
  double caller_seconds_ = 0.0, build_seconds_ = 0.0;
};

}  // namespace ts::sdf
