#include "sdf/exact_sdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

#include "core/error.h"
#include "core/mesh_io.h"
#include "gpu/context.h"
#include "sdf/openvdb_compare.h"
#include "sdf/scan_convert.h"
#include "sdf/vdb_io.h"
#include "tests/test_meshes.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

TEST(ExactDistance, SphereMatchesAnalyticWithinTheFacetError) {
  const double r = 1.0;
  const TriangleMesh sphere = test::icosphere(r, 3);
  const ExactDistance exact(sphere);
  // Facets of an inscribed icosphere sit at most r (1 - cos(edge angle)) inside the sphere.
  const double facet = 0.01;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const double d = exact.signed_distance(p, SignMethod::Pseudonormal);
    EXPECT_NEAR(d, p.norm() - r, facet) << p.transpose();
    EXPECT_EQ(d < 0, exact.signed_distance(p, SignMethod::Winding) < 0) << p.transpose();
  }
}

TEST(ExactDistance, ClassifiesFaceEdgeAndVertexOfACube) {
  const ExactDistance exact(test::box_mesh({0, 0, 0}, {1, 1, 1}));
  // (0.5, 0.5) would be on the diagonal both top triangles share: an edge, with the face's normal.
  EXPECT_EQ(exact.closest({0.3, 0.6, 2.0}).feature, Feature::Face);
  EXPECT_EQ(exact.closest({0.5, 2.0, 2.0}).feature, Feature::Edge);
  EXPECT_EQ(exact.closest({2.0, 2.0, 2.0}).feature, Feature::Vertex);
  const ClosestPoint corner = exact.closest({2.0, 2.0, 2.0});
  EXPECT_LT((exact.feature_normal(corner) - Eigen::Vector3d::Constant(1.0 / std::sqrt(3.0))).norm(), 1e-12);
  EXPECT_NEAR(exact.signed_distance({0.5, 0.5, 0.5}, SignMethod::Pseudonormal), -0.5, 1e-15);
}

TEST(ExactDistance, WindingNumberKeepsTheInsideOfAnOpenMesh) {
  TriangleMesh open = test::icosphere(1.0, 2);
  open.triangles.resize(open.triangles.size() - 3);  // punch a small hole
  const ExactDistance exact(open);
  EXPECT_GT(exact.winding_number({0, 0, 0}), 0.9);
  EXPECT_LT(exact.winding_number({0, 0, 3}), 0.1);
  EXPECT_LT(exact.signed_distance({0.1, 0.2, 0.0}, SignMethod::Winding), 0.0);
}

TEST(ExactSdf, GpuScanConversionMatchesTheExactGrid) {
  gpu::Context context;
  for (const auto& mesh : {test::box_mesh({-0.5, -0.4, -0.3}, {0.5, 0.4, 0.3}), test::icosphere(0.5, 2)}) {
    SdfSettings settings;
    settings.resolution = 24;
    const GridSpec spec = make_grid(bounding_box(mesh), settings);
    const auto exact = exact_sdf_grid(mesh, spec, 3.0, SignMethod::Pseudonormal);
    ScanConvertOptions options;
    const auto gpu = scan_convert(context, mesh, compute_pseudonormals(mesh), spec, options);
    const GridComparison c = compare_grids(*gpu.grid, *exact, spec.voxel_size, 3.0 * spec.voxel_size);
    EXPECT_GT(c.voxels, 1000u);
    EXPECT_LE(c.max, 1e-3);
    EXPECT_EQ(c.sign_disagreements, 0u);
  }
}

TEST(ExactSdf, OpenVdbIsCloseButExactIsCloser) {
  const TriangleMesh mesh = load_mesh(test::asset("bunny.obj"));
  SdfSettings settings;
  settings.resolution = 24;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  const auto exact = exact_sdf_grid(mesh, spec, 3.0, SignMethod::Pseudonormal);
  const auto vdb = openvdb_level_set(mesh, spec.voxel_size, 3.0);
  const GridComparison c = compare_grids(*vdb, *exact, spec.voxel_size, 3.0 * spec.voxel_size);
  EXPECT_LT(c.mean, 0.05);   // statistical agreement (peers.md: OpenVDB is approximate)
  EXPECT_LT(static_cast<double>(c.sign_disagreements), 0.01 * static_cast<double>(c.voxels));
  EXPECT_NE(format_comparison(c, c, c).find("closer to exact"), std::string::npos);
}

TEST(VdbIo, RoundTripAndVdbPrintSeeALevelSet) {
  const auto dir = test::temp_dir();
  const TriangleMesh mesh = test::icosphere(0.5, 1);
  SdfSettings settings;
  settings.resolution = 16;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  write_vdb(dir / "s.vdb", exact_sdf_grid(mesh, spec, 3.0, SignMethod::Pseudonormal), {{"tetrasand:test", "yes"}});
  const auto back = read_level_set(dir / "s.vdb");
  EXPECT_EQ(back->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_NEAR(back->voxelSize()[0], spec.voxel_size, 1e-12);
  std::string out;
  FILE* pipe = ::popen(("vdb_print -l '" + (dir / "s.vdb").string() + "' 2>&1").c_str(), "r");
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
  EXPECT_EQ(::pclose(pipe), 0) << out;
  EXPECT_NE(out.find("level set"), std::string::npos) << out;
  EXPECT_NE(out.find("surface"), std::string::npos) << out;
}

TEST(VdbIo, BadFilesAreClearErrors) {
  const auto dir = test::temp_dir();
  EXPECT_THROW(read_level_set(dir / "missing.vdb"), InputError);
  std::ofstream(dir / "text.vdb") << "not a vdb";
  EXPECT_THROW(read_level_set(dir / "text.vdb"), InputError);
  auto fog = openvdb::FloatGrid::create(0.0f);
  fog->getAccessor().setValue(openvdb::Coord(0, 0, 0), 1.0f);
  fog->setGridClass(openvdb::GRID_FOG_VOLUME);
  write_vdb(dir / "fog.vdb", fog);
  try {
    read_level_set(dir / "fog.vdb");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("none is a level set"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ts::sdf
