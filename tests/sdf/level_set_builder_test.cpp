// The level set's parallel build (sdf/level_set_builder.h) against the one-accessor insertion it
// replaced: the same tree, bit for bit (active voxels, every leaf value, internal tiles after the
// signed flood fill), on synthetic bands fed in awkward slabs and on real meshes scanned in slabs of
// 3 and 13 layers.
#include "sdf/level_set_builder.h"

#include <gtest/gtest.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <cstring>
#include <random>

#include "core/mesh_io.h"
#include "gpu/context.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

using Leaf = openvdb::FloatTree::LeafNodeType;

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// Every value of `a` (voxels, tiles, inactive ones too) bit-equal in `b` with the same state, the
// same node counts and background: with the values held the other way round, the trees are equal.
void expect_same_tree(const openvdb::FloatTree& a, const openvdb::FloatTree& b) {
  ASSERT_TRUE(same_bits(a.background(), b.background()));
  ASSERT_EQ(a.nodeCount(), b.nodeCount());
  ASSERT_EQ(a.activeVoxelCount(), b.activeVoxelCount());
  ASSERT_EQ(a.activeTileCount(), b.activeTileCount());
  for (auto leaf = a.cbeginLeaf(); leaf; ++leaf) {
    const Leaf* other = b.probeConstLeaf(leaf->origin());
    ASSERT_NE(other, nullptr) << leaf->origin();
    ASSERT_EQ(leaf->getValueMask(), other->getValueMask()) << leaf->origin();
    ASSERT_EQ(std::memcmp(leaf->buffer().data(), other->buffer().data(), Leaf::SIZE * sizeof(float)), 0)
        << leaf->origin();
  }
  openvdb::tree::ValueAccessor<const openvdb::FloatTree> accessor(b);
  for (auto tile = a.cbeginValueAll(); tile; ++tile) {
    if (tile.getLevel() == 0) continue;  // leaf values: compared above
    ASSERT_TRUE(same_bits(*tile, accessor.getValue(tile.getCoord()))) << tile.getCoord();
    ASSERT_EQ(tile.isValueOn(), accessor.isValueOn(tile.getCoord())) << tile.getCoord();
  }
}

// A band-like set: voxels near a sphere of radius r about the grid's centre, 4 floats each.
struct SyntheticBand {
  GridSpec spec;
  std::vector<std::size_t> voxels;  // grid order (x fastest, then y, then z)
  std::vector<float> values;
};

SyntheticBand sphere_band(const Eigen::Vector3i& dims, const Eigen::Vector3i& offset, unsigned seed) {
  SyntheticBand b;
  b.spec.dims = dims;
  b.spec.index_offset = offset;
  b.spec.voxel_size = 0.01;
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> jitter(-0.5f, 0.5f);
  const Eigen::Vector3d centre = dims.cast<double>() / 2.0;
  const double r = 0.35 * dims.minCoeff();
  for (int k = 0; k < dims.z(); ++k)
    for (int j = 0; j < dims.y(); ++j)
      for (int i = 0; i < dims.x(); ++i) {
        const double d = (Eigen::Vector3d(i, j, k) - centre).norm() - r;
        if (std::abs(d) >= 3.0) continue;
        b.voxels.push_back(b.spec.linear_index(i, j, k));
        b.values.insert(b.values.end(),
                        {jitter(random), jitter(random), jitter(random), static_cast<float>(d)});
      }
  return b;
}

// `band` cut into slabs of `layers` z-layers, handed to `consume(slab)` in order; slab indices start
// at each slab's first layer, as the scanner reads them back.
template <typename F>
void for_each_slab(const SyntheticBand& band, int layers, F&& consume) {
  const std::size_t layer =
      static_cast<std::size_t>(band.spec.dims.x()) * static_cast<std::size_t>(band.spec.dims.y());
  std::size_t next = 0;
  for (int z0 = 0; z0 < band.spec.dims.z(); z0 += layers) {
    const std::size_t end_index = static_cast<std::size_t>(std::min(z0 + layers, band.spec.dims.z())) * layer;
    std::vector<std::size_t> local;
    const std::size_t first = next;
    for (; next < band.voxels.size() && band.voxels[next] < end_index; ++next)
      local.push_back(band.voxels[next] - static_cast<std::size_t>(z0) * layer);
    consume(BandSlab{z0, local, std::span<const float>(band.values).subspan(4 * first, 4 * local.size())});
  }
}

openvdb::FloatTree::Ptr serial_tree(const SyntheticBand& band, int layers, float background) {
  auto tree = std::make_shared<openvdb::FloatTree>(background);
  const float h = static_cast<float>(band.spec.voxel_size);
  for_each_slab(band, layers, [&](const BandSlab& slab) { insert_band_serial(*tree, band.spec, h, slab); });
  openvdb::tools::signedFloodFill(*tree);
  return tree;
}

openvdb::FloatTree::Ptr parallel_tree(const SyntheticBand& band, int layers, float background,
                                      bool overlapped) {
  auto tree = std::make_shared<openvdb::FloatTree>(background);
  LevelSetBuilder builder(*tree, band.spec, static_cast<float>(band.spec.voxel_size), overlapped);
  for_each_slab(band, layers, [&](const BandSlab& slab) { builder.add(slab); });
  builder.finish();
  openvdb::tools::signedFloodFill(*tree);
  return tree;
}

TEST(LevelSetBuilder, SlabsOfAnyLayerCountBuildTheSerialTreeBitForBit) {
  // Offsets not a multiple of 8 (negative too) put leaf boundaries inside slabs and slabs inside leaves.
  const SyntheticBand band = sphere_band({45, 38, 51}, {-13, 5, -21}, 7);
  ASSERT_GT(band.voxels.size(), 10000u);
  const float background = 0.03f;
  const auto reference = serial_tree(band, 51, background);
  for (int layers : {1, 3, 8, 13, 51}) {
    for (bool overlapped : {false, true}) {
      SCOPED_TRACE(testing::Message() << layers << " layers a slab, overlapped " << overlapped);
      expect_same_tree(*reference, *parallel_tree(band, layers, background, overlapped));
      expect_same_tree(*parallel_tree(band, layers, background, overlapped), *reference);
    }
  }
}

TEST(LevelSetBuilder, EmptySlabsAndAnEmptyBandLeaveOnlyTheBackground) {
  SyntheticBand band = sphere_band({20, 20, 40}, {0, 0, 0}, 3);
  band.voxels.clear();
  band.values.clear();
  const auto tree = parallel_tree(band, 5, 0.5f, true);
  EXPECT_EQ(tree->activeVoxelCount(), 0u);
  EXPECT_EQ(tree->leafCount(), 0u);
  expect_same_tree(*serial_tree(band, 5, 0.5f), *tree);
}

// The scan's level set against the serial insertion of the same band (taken from the dense copy:
// band voxels are the ones with a gradient or inside the band; the others hold +-band exactly with
// none), then flood-filled alike.
openvdb::FloatTree::Ptr serial_from_dense(const ScanConvertResult& result, float background) {
  auto tree = std::make_shared<openvdb::FloatTree>(background);
  openvdb::tree::ValueAccessor<openvdb::FloatTree> accessor(*tree);
  const GridSpec& spec = result.dense.spec;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const Eigen::Vector4f& v = result.dense.values[spec.linear_index(i, j, k)];
        if (v.head<3>().isZero() && std::abs(v.w()) == background) continue;
        accessor.setValue(
            openvdb::Coord(spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k),
            v.w());
      }
  openvdb::tools::signedFloodFill(*tree);
  return tree;
}

TEST(LevelSetBuilder, RealMeshesScannedInSlabsOf3And13LayersGiveTheSerialTree) {
  gpu::Context context;
  for (const char* name : {"knot1", "fandisk"}) {
    const TriangleMesh mesh = load_mesh(test::cgal_mesh(name));
    SdfSettings settings;
    settings.resolution = 48;
    const GridSpec spec = make_grid(bounding_box(mesh), settings);
    for (int layers : {3, 13}) {
      SCOPED_TRACE(testing::Message() << name << ", " << layers << " layers a slab");
      ScanConvertOptions options;
      options.keep_dense = true;
      options.max_slab_bytes = bytes_per_layer(spec) * static_cast<std::size_t>(layers);
      const auto result = scan_convert(context, mesh, compute_pseudonormals(mesh), spec, options);
      ASSERT_EQ(result.stats.layers_per_slab, layers);
      EXPECT_EQ(result.grid->activeVoxelCount(), result.stats.band_voxels);
      expect_same_tree(*serial_from_dense(result, result.grid->background()), result.grid->tree());
    }
  }
}

TEST(LevelSetBuilder, ScanStatsSplitTheTimeIntoGpuReadbackAndHostBuild) {
  gpu::Context context;
  const TriangleMesh mesh = load_mesh(test::cgal_mesh("knot1"));
  SdfSettings settings;
  settings.resolution = 64;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  ScanConvertOptions options;
  options.max_slab_bytes = bytes_per_layer(spec) * 16;
  const ScanConvertStats s = scan_convert(context, mesh, compute_pseudonormals(mesh), spec, options).stats;
  EXPECT_GE(s.slabs, 3);
  EXPECT_GT(s.gpu_seconds, 0.0);
  EXPECT_GT(s.readback_seconds, 0.0);
  EXPECT_GT(s.host_build_seconds, 0.0);
  EXPECT_GT(s.leaf_build_seconds, 0.0);
  // The parts are disjoint stretches of the call on its thread.
  EXPECT_LE(s.gpu_seconds + s.readback_seconds + s.host_build_seconds, s.seconds);
}

}  // namespace
}  // namespace ts::sdf
