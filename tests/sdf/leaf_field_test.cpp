// The field built and kept on the GPU by the scan conversion (sdf::LeafField): what GLSL reads of it
// through shaders/common/sparse_field.glsl (compiled with TS_FIELD_LEAVES) must be, voxel for voxel
// and bit for bit, what it reads of the host's NanoVDB field from the same scan (sdf::SparseField), on
// and off the band, on real closed meshes and both scan paths; two builds must be byte-identical; and
// nothing of the field may be read back when the host's level set is not asked for.
#include "sdf/leaf_field.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/mesh_io.h"
#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/params.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"
#include "sdf/sparse_field.h"
#include "shaders/common/layouts.h"
#include "shaders/test/bindings.h"
#include "tests/sdf/field_probe.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

struct Case {
  std::string mesh;  // assets/<mesh>.obj, or cgal:<name> for libcgal-demo's
  ScanMethod method;
  int resolution;  // voxels along the longest side
};

std::ostream& operator<<(std::ostream& out, const Case& c) {
  return out << c.mesh << "/" << scan_method_name(c.method) << "@" << c.resolution;
}

TriangleMesh load_case_mesh(const std::string& name) {
  if (name.rfind("cgal:", 0) == 0) return load_mesh(test::cgal_mesh(name.substr(5)));
  return load_mesh(test::asset(name + ".obj"));
}

class LeafFieldTest : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    mesh_ = load_case_mesh(GetParam().mesh);
    SdfSettings settings;
    settings.resolution = GetParam().resolution;
    spec_ = make_grid(bounding_box(mesh_), settings);
    normals_ = compute_pseudonormals(mesh_);
  }

  // Both fields from one scan: the host's level set (index space) and the GPU's leaf field. Slabs of
  // 16 layers, so leaves are built across several slabs (2 for the flat torus).
  ScanConvertResult scan(bool build_grid) {
    ScanConvertOptions options;
    options.method = GetParam().method;
    options.band = kBand;
    options.index_space_grid = true;
    options.build_grid = build_grid;
    options.gpu_field = true;
    options.max_slab_bytes = bytes_per_layer(spec_) * 20 + 1;
    return scan_convert(context_, mesh_, normals_, spec_, options);
  }

  // Every voxel of the grid and a ring of one voxel around it, grid-local.
  std::vector<Eigen::Vector4f> every_voxel() const {
    std::vector<Eigen::Vector4f> points;
    for (int k = -1; k <= spec_.dims.z(); ++k)
      for (int j = -1; j <= spec_.dims.y(); ++j)
        for (int i = -1; i <= spec_.dims.x(); ++i) points.emplace_back(i, j, k, 0.0f);
    return points;
  }

  static constexpr double kBand = 3.0;
  gpu::Context context_;
  TriangleMesh mesh_;
  GridSpec spec_;
  Pseudonormals normals_;
};

TEST_P(LeafFieldTest, GlslReadsTheSameValueAsTheHostFieldAtEveryVoxelOnAndOffTheBand) {
  ScanConvertResult result = scan(true);
  ASSERT_TRUE(result.field.has_value());
  ASSERT_GE(result.stats.slabs, 2);
  const LeafField& leaves = *result.field;
  const SparseField host(*result.grid, spec_, kBand);
  EXPECT_EQ(leaves.band_voxels(), host.band_voxels());
  EXPECT_EQ(leaves.band_voxels(), result.stats.band_voxels);
  EXPECT_LE(leaves.band_leaves(), leaves.slots());
  EXPECT_EQ(leaves.background(), result.grid->background());

  const std::vector<Eigen::Vector4f> points = every_voxel();
  const auto expected = test::probe_field(host, points, 0);
  const auto actual = test::probe_field(leaves, points, 0);
  std::size_t differ = 0, inside = 0, band = 0;
  for (std::size_t n = 0; n < points.size(); ++n) {
    const float e = expected[n].x(), a = actual[n].x();
    if (std::memcmp(&e, &a, sizeof(float)) != 0 && differ++ < 5) {
      ADD_FAILURE() << "voxel " << points[n].transpose() << ": host " << e << ", GPU field " << a;
    }
    inside += e == -leaves.background();
    band += std::abs(e) < leaves.background();
  }
  EXPECT_EQ(differ, 0u) << "of " << points.size() << " voxels";
  // Both signs off the band and the band itself were compared.
  EXPECT_GT(inside, 100u);
  EXPECT_GT(band, 1000u);
}

TEST_P(LeafFieldTest, SampledValuesAndGradientsMatchTheHostFieldBitForBit) {
  ScanConvertResult result = scan(true);
  const SparseField host(*result.grid, spec_, kBand);
  std::vector<Eigen::Vector4f> points;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int n = 0; n < 4000; ++n)
    points.emplace_back(u(rng) * static_cast<float>(spec_.dims.x() - 1), u(rng) * static_cast<float>(spec_.dims.y() - 1),
                        u(rng) * static_cast<float>(spec_.dims.z() - 1), 0.0f);
  const auto expected = test::probe_field(host, points, 2);
  const auto actual = test::probe_field(*result.field, points, 2);
  ASSERT_EQ(expected.size(), actual.size());
  EXPECT_EQ(std::memcmp(expected.data(), actual.data(), expected.size() * sizeof(Eigen::Vector4f)), 0);
}

TEST_P(LeafFieldTest, TwoBuildsAreByteIdenticalAndNothingOfTheFieldIsReadBack) {
  const ScanConvertResult first = scan(false);
  const ScanConvertResult second = scan(false);
  EXPECT_EQ(first.stats.readback_bytes, 0u);
  EXPECT_FALSE(first.grid);
  const LeafField::HostCopy a = first.field->download(), b = second.field->download();
  ASSERT_GT(a.values.size(), 0u);
  EXPECT_EQ(a.index, b.index);
  ASSERT_EQ(a.values.size(), b.values.size());
  EXPECT_EQ(std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(float)), 0);
  // Every cell resolved: a slot or inside/outside, none left pending.
  for (std::uint32_t entry : a.index) ASSERT_TRUE(entry < first.field->band_leaves() || entry >= TS_LEAF_INSIDE);
  EXPECT_EQ(first.stats.band_voxels, first.field->band_voxels());
}

INSTANTIATE_TEST_SUITE_P(RealClosedMeshes, LeafFieldTest,
                         ::testing::Values(Case{"bunny", ScanMethod::Compute, 56}, Case{"bunny", ScanMethod::Geometry, 56},
                                           Case{"torus", ScanMethod::Compute, 48}, Case{"torus", ScanMethod::Geometry, 48},
                                           Case{"trefoil", ScanMethod::Compute, 56},
                                           Case{"trefoil", ScanMethod::Geometry, 56},
                                           Case{"cgal:elephant", ScanMethod::Compute, 48}),
                         [](const ::testing::TestParamInfo<Case>& p) {
                           std::string name = p.param.mesh + "_" + scan_method_name(p.param.method);
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

TEST(LeafFieldBound, CoversTheBandLeavesWithoutFarOverestimating) {
  gpu::Context context;
  const TriangleMesh mesh = load_mesh(test::asset("bunny.obj"));
  SdfSettings settings;
  settings.resolution = 64;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  ScanConvertOptions options;
  options.band = 4.0;
  options.build_grid = false;
  options.gpu_field = true;
  const ScanConvertResult result = scan_convert(context, mesh, compute_pseudonormals(mesh), spec, options);
  const std::size_t bound = band_leaf_bound(mesh, spec, 4.0);
  EXPECT_EQ(result.field->slots(), bound);
  EXPECT_LE(result.field->band_leaves(), bound);
  EXPECT_LT(static_cast<double>(bound), 2.0 * static_cast<double>(result.field->band_leaves()));
}

// TETRASAND_GPU_MEMORY_MIB caps what a field may take (so a test meets the out-of-memory refusal on
// llvmpipe); a value that is not a positive number of MiB is the user's error, named as such.
TEST(LeafFieldMemory, TheCapFromTheEnvironmentIsInMibAndNonsenseIsRefused) {
  ::setenv("TETRASAND_GPU_MEMORY_MIB", "0.5", 1);
  const std::size_t half = gpu_field_memory_limit();
  std::string refused;
  for (const char* bad : {"abc", "-2", "0", "12MiB", "nan"}) {
    ::setenv("TETRASAND_GPU_MEMORY_MIB", bad, 1);
    try {
      gpu_field_memory_limit();
    } catch (const InputError& e) {
      if (std::string(e.what()).find("TETRASAND_GPU_MEMORY_MIB") != std::string::npos) refused += bad;
    }
  }
  ::unsetenv("TETRASAND_GPU_MEMORY_MIB");
  EXPECT_EQ(half, std::size_t{1} << 19);
  EXPECT_EQ(refused, "abc-2012MiBnan");
}

}  // namespace
}  // namespace ts::sdf
