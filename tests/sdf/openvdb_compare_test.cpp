// tetrasand's SDFs against OpenVDB's meshToLevelSet, both judged by exact distance.
#include "sdf/openvdb_compare.h"

#include <gtest/gtest.h>

#include "gpu/context.h"
#include "sdf/exact_sdf.h"
#include "sdf/scan_convert.h"
#include "tests/test_meshes.h"

namespace ts::sdf {
namespace {

TEST(CompareGrids, CountsDifferencesInVoxelsAndSignFlips) {
  const double h = 0.5;
  auto reference = openvdb::FloatGrid::create(1.5f), other = openvdb::FloatGrid::create(1.5f);
  auto r = reference->getAccessor();
  auto o = other->getAccessor();
  r.setValue(openvdb::Coord(0, 0, 0), 0.25f), o.setValue(openvdb::Coord(0, 0, 0), 0.25f);    // equal
  r.setValue(openvdb::Coord(1, 0, 0), 0.5f), o.setValue(openvdb::Coord(1, 0, 0), -0.5f);     // 2 voxels, flipped
  r.setValue(openvdb::Coord(2, 0, 0), -1.0f), o.setValue(openvdb::Coord(2, 0, 0), -0.75f);   // half a voxel
  r.setValue(openvdb::Coord(3, 0, 0), 1.5f);  // outside the band: not compared
  const GridComparison c = compare_grids(*other, *reference, h, 1.5);
  EXPECT_EQ(c.voxels, 3u);
  EXPECT_EQ(c.sign_disagreements, 1u);
  EXPECT_DOUBLE_EQ(c.max, 2.0);
  EXPECT_DOUBLE_EQ(c.mean, 2.5 / 3.0);
}

TEST(OpenVdbComparison, SphereAgreesStatisticallyAndTheGpuPathIsCloserToExact) {
  const TriangleMesh sphere = test::icosphere(0.5, 3);
  SdfSettings settings;
  settings.resolution = 24;
  const GridSpec spec = make_grid(bounding_box(sphere), settings);
  const double band = 3.0, band_world = band * spec.voxel_size;
  const auto exact = exact_sdf_grid(sphere, spec, band, SignMethod::Pseudonormal);
  const auto vdb = openvdb_level_set(sphere, spec.voxel_size, band);
  EXPECT_EQ(vdb->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_NEAR(vdb->voxelSize()[0], spec.voxel_size, 1e-12);

  gpu::Context context;
  const auto gpu = scan_convert(context, sphere, compute_pseudonormals(sphere), spec, ScanConvertOptions{});

  const GridComparison vdb_vs_exact = compare_grids(*vdb, *exact, spec.voxel_size, band_world);
  const GridComparison gpu_vs_exact = compare_grids(*gpu.grid, *exact, spec.voxel_size, band_world);
  const GridComparison gpu_vs_vdb = compare_grids(*gpu.grid, *vdb, spec.voxel_size, band_world);
  EXPECT_GT(vdb_vs_exact.voxels, 1000u);
  // OpenVDB is approximate (notes/peers.md): judged by statistics, never by its maximum.
  EXPECT_LT(vdb_vs_exact.mean, 0.05);
  EXPECT_LT(static_cast<double>(vdb_vs_exact.sign_disagreements), 0.01 * static_cast<double>(vdb_vs_exact.voxels));
  EXPECT_LE(gpu_vs_exact.max, 1e-3);
  EXPECT_EQ(gpu_vs_exact.sign_disagreements, 0u);
  EXPECT_LT(gpu_vs_exact.mean, vdb_vs_exact.mean);
  EXPECT_NEAR(gpu_vs_vdb.mean, vdb_vs_exact.mean, 0.01);

  const std::string report = format_comparison(gpu_vs_exact, vdb_vs_exact, gpu_vs_vdb);
  EXPECT_NE(report.find("tetrasand GPU vs exact"), std::string::npos) << report;
  EXPECT_NE(report.find("OpenVDB vs exact"), std::string::npos) << report;
  EXPECT_NE(report.find("closer to exact: tetrasand GPU"), std::string::npos) << report;
}

}  // namespace
}  // namespace ts::sdf
