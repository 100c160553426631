// The compute-shader scan conversion (ScanMethod::Compute, sdf/compute_scan.h) against the CPU exact
// distance (sdf/exact_sdf.h, double precision) and against the geometry path: every band voxel
// present and within 1e-3 voxel, no wrong sign anywhere in the grid, the geometry path's band voxel
// set, and the same bytes however the work is split and whenever it runs.
#include "sdf/compute_scan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <set>
#include <tuple>

#include "core/mesh_io.h"
#include "core/mesh_report.h"
#include "core/primitives.h"
#include "gpu/context.h"
#include "gpu/shader_library.h"
#include "sdf/exact_sdf.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_convert.h"
#include "shaders/sdf/bindings.h"
#include "tests/test_meshes.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

using test::box_mesh;
using test::grid_around;

struct Agreement {
  std::size_t band_voxels = 0, missing = 0, sign_errors = 0;
  std::size_t band_upper = 0;  // voxels with |exact| < band + 1e-3: at most the band a field may hold
  double max_error_voxels = 0.0;
};

// Every voxel of the dense field against the exact signed distance (pseudonormal signs) of `mesh`.
Agreement compare_with_exact(const TriangleMesh& mesh, const DenseSdf& dense, double band) {
  const ExactDistance exact(mesh);
  const GridSpec& spec = dense.spec;
  Agreement a;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const double truth =
            exact.signed_distance(spec.voxel_center(i, j, k), SignMethod::Pseudonormal) / spec.voxel_size;
        const double value = dense.values[spec.linear_index(i, j, k)].w() / spec.voxel_size;
        if (std::abs(truth) < band + 1e-3) ++a.band_upper;
        if (std::abs(truth) < band - 1e-3) {
          ++a.band_voxels;
          if (!(std::abs(value) < band - 1e-6)) {
            ++a.missing;
            continue;
          }
          a.max_error_voxels = std::max(a.max_error_voxels, std::abs(value - truth));
        }
        if (std::abs(truth) > 1e-3 && (value < 0) != (truth < 0)) ++a.sign_errors;
      }
  return a;
}

bool same_bytes(const DenseSdf& a, const DenseSdf& b) {
  return a.values.size() == b.values.size() &&
         std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(Eigen::Vector4f)) == 0;
}

class ComputeScan : public ::testing::Test {
 protected:
  gpu::Context context;
  ScanConvertResult run(const TriangleMesh& mesh, const GridSpec& spec, ScanMethod method,
                        std::size_t max_slab_bytes = std::size_t{1} << 30, int brick = 0) {
    ScanConvertOptions options;
    options.method = method;
    options.compute_brick = brick;
    options.keep_dense = true;
    options.build_grid = false;
    options.max_slab_bytes = max_slab_bytes;
    return scan_convert(context, mesh, compute_pseudonormals(mesh), spec, options);
  }
};

TEST_F(ComputeScan, RealClosedMeshesAreExactToAThousandthVoxelWithNoSignErrorAndNoMissingVoxel) {
  // Coarse grids (a few seconds each on llvmpipe): many triangles per voxel, many ties and near-ties.
  for (const char* name : {"knot1", "fandisk"}) {
    const TriangleMesh mesh = load_mesh(test::cgal_mesh(name));
    ReportOptions report_options;
    report_options.self_intersections = false;
    ASSERT_TRUE(analyze_mesh(mesh, report_options).closed()) << name;
    SdfSettings settings;
    settings.resolution = 28;
    const GridSpec spec = make_grid(bounding_box(mesh), settings);
    const auto result = run(mesh, spec, ScanMethod::Compute);
    EXPECT_EQ(result.stats.method, ScanMethod::Compute);
    EXPECT_GT(result.stats.brick_pairs, 0u);
    EXPECT_EQ(result.stats.draws, 0);
    const Agreement a = compare_with_exact(mesh, result.dense, 3.0);
    EXPECT_GT(a.band_voxels, 3000u) << name;
    EXPECT_EQ(a.missing, 0u) << name;
    EXPECT_EQ(a.sign_errors, 0u) << name;
    EXPECT_LE(a.max_error_voxels, 1e-3) << name;
    // Voxels within 1e-3 of the band's edge may fall either way.
    EXPECT_GE(result.stats.band_voxels, a.band_voxels) << name;
    EXPECT_LE(result.stats.band_voxels, a.band_upper) << name;
  }
}

TEST_F(ComputeScan, BandVoxelsDistancesAndSignsAreTheGeometryPaths) {
  const TriangleMesh mesh = load_mesh(test::cgal_mesh("knot1"));
  SdfSettings settings;
  settings.resolution = 32;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  const auto compute = run(mesh, spec, ScanMethod::Compute);
  const auto geometry = run(mesh, spec, ScanMethod::Geometry);
  ASSERT_EQ(compute.stats.band_voxels, geometry.stats.band_voxels);
  const float band = static_cast<float>(3.0 * spec.voxel_size);
  std::size_t different_set = 0, different_sign = 0;
  double worst = 0.0;
  for (std::size_t v = 0; v < compute.dense.values.size(); ++v) {
    const float c = compute.dense.values[v].w(), g = geometry.dense.values[v].w();
    if ((std::abs(c) < band) != (std::abs(g) < band)) ++different_set;
    if ((c < 0) != (g < 0) && std::abs(g) > 1e-3 * spec.voxel_size) ++different_sign;
    if (std::abs(g) < band) worst = std::max(worst, std::abs(std::abs(c) - std::abs(g)) / spec.voxel_size);
  }
  EXPECT_EQ(different_set, 0u);
  EXPECT_EQ(different_sign, 0u);
  // One formula (sdf/voxel_value.glsl) on both paths: the nearest distance is the same float.
  EXPECT_LE(worst, 1e-6);
}

TEST_F(ComputeScan, TwoRunsAnySlabSplitAndEitherBrickSizeGiveTheSameBytes) {
  const TriangleMesh mesh = load_mesh(test::cgal_mesh("knot1"));
  SdfSettings settings;
  settings.resolution = 24;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  const auto first = run(mesh, spec, ScanMethod::Compute);
  const auto second = run(mesh, spec, ScanMethod::Compute);
  // Slabs of a few layers: different pair ranges per dispatch, bricks cut by slab boundaries.
  const auto sliced = run(mesh, spec, ScanMethod::Compute, bytes_per_layer(spec) * 5);
  // 4^3 bricks (a hardware GPU's choice; 2^3 on llvmpipe): other pairs, other groups, the same field.
  const auto large_bricks = run(mesh, spec, ScanMethod::Compute, std::size_t{1} << 30, 4);
  ASSERT_GT(sliced.stats.slabs, first.stats.slabs);
  ASSERT_NE(large_bricks.stats.brick_pairs, first.stats.brick_pairs);
  EXPECT_TRUE(same_bytes(first.dense, second.dense));
  EXPECT_TRUE(same_bytes(first.dense, sliced.dense));
  EXPECT_TRUE(same_bytes(first.dense, large_bricks.dense));
}

TEST_F(ComputeScan, CubeWithVoxelsEquidistantToTwoFacesIsDeterministicAndExact) {
  // Voxel centres on the cube's diagonal planes (x = y, ...) are equally near two faces, and on its
  // faces' diagonals equally near both triangles of a face: the lower triangle index must win
  // every time, whatever order the work groups run in.
  const TriangleMesh cube = box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  const GridSpec spec = grid_around(cube, 1.0 / 16.0, 4);
  const auto first = run(cube, spec, ScanMethod::Compute);
  const auto second = run(cube, spec, ScanMethod::Compute, bytes_per_layer(spec) * 3);
  EXPECT_TRUE(same_bytes(first.dense, second.dense));
  const Agreement a = compare_with_exact(cube, first.dense, 3.0);
  EXPECT_GT(a.band_voxels, 1000u);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_EQ(a.sign_errors, 0u);
  EXPECT_LE(a.max_error_voxels, 1e-3);
}

TEST_F(ComputeScan, DegenerateTrianglesAreSkippedWithoutHolesOrNaN) {
  TriangleMesh cube = box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  cube.triangles.push_back({0, 0, 1});  // zero area, on an edge of the cube
  const GridSpec spec = grid_around(cube, 1.0 / 16.0, 4);
  const auto result = run(cube, spec, ScanMethod::Compute);
  EXPECT_EQ(result.stats.degenerate_triangles, 1u);
  for (const Eigen::Vector4f& v : result.dense.values) ASSERT_TRUE(v.allFinite());
  const Agreement a = compare_with_exact(box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}), result.dense, 3.0);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_EQ(a.sign_errors, 0u);
  EXPECT_LE(a.max_error_voxels, 1e-3);
}

TEST_F(ComputeScan, NeedleTriangleHasItsWholeBandAtExactDistance) {
  // A single sliver (angle ~0.006 degrees at one corner) spanning the grid diagonally, as an open
  // mesh: the unsigned distance must be exact on its whole band.
  TriangleMesh needle;
  needle.vertices = {{-1.0, 0.0, 0.1}, {1.0, 0.0, -0.1}, {1.0, 0.0002, -0.1}};
  needle.triangles = {{0, 1, 2}};
  const GridSpec spec = grid_around(needle, 1.0 / 16.0, 4);
  const auto result = run(needle, spec, ScanMethod::Compute);
  EXPECT_EQ(result.stats.needle_triangles, 1u);
  const ExactDistance exact(needle);
  std::size_t band = 0, missing = 0;
  double worst = 0.0;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const double truth = exact.closest(spec.voxel_center(i, j, k)).distance / spec.voxel_size;
        if (truth >= 2.999) continue;
        ++band;
        const double value = std::abs(result.dense.values[spec.linear_index(i, j, k)].w()) / spec.voxel_size;
        if (!(value < 3.0)) {
          ++missing;
          continue;
        }
        worst = std::max(worst, std::abs(value - truth));
      }
  EXPECT_GT(band, 500u);
  EXPECT_EQ(missing, 0u);
  EXPECT_LE(worst, 1e-3);
}

// Every (triangle, brick) with a voxel centre of the brick within `band` of the triangle (brute force
// over the whole grid) is among the pairs, and each row lists its triangles in ascending order.
void expect_every_band_brick_paired(const TriangleMesh& sphere, const GridSpec& spec,
                                    const std::vector<gpu::layout::SdfTriangle>& triangles,
                                    const std::vector<std::uint32_t>& usable, double band, int side) {
  const BrickPairs pairs = build_brick_pairs(triangles, usable, spec, band + 0.25, side);
  EXPECT_EQ(pairs.brick, side);
  const Eigen::Vector3i bricks = (spec.dims.array() + side - 1) / side;
  ASSERT_EQ(pairs.row_begin.size(), static_cast<std::size_t>(bricks.z()) + 1);
  EXPECT_EQ(pairs.row_begin.back(), pairs.count());
  std::set<std::tuple<std::uint32_t, int, int, int>> paired;  // triangle, brick x, y, z
  for (int r = 0; r < bricks.z(); ++r)
    for (std::uint32_t p = pairs.row_begin[r]; p < pairs.row_begin[r + 1]; ++p) {
      if (p > pairs.row_begin[r]) {
        ASSERT_LE(pairs.words[2 * (p - 1)], pairs.words[2 * p]);
      }
      const std::uint32_t key = pairs.words[2 * p + 1];
      paired.insert({pairs.words[2 * p], static_cast<int>(key & 0xFFFF), static_cast<int>(key >> 16), r});
    }
  // Brute force: every voxel centre of the grid against every triangle.
  const ExactDistance exact(sphere);
  std::size_t needed = 0, missing = 0;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i)
        for (std::uint32_t t : usable) {
          if (!(exact.closest_on(spec.voxel_center(i, j, k), t).distance / spec.voxel_size < band)) continue;
          ++needed;
          const int b = side;
          missing += paired.count({t, i / b, j / b, k / b}) ? 0 : 1;
        }
  EXPECT_GT(needed, 10000u);
  EXPECT_EQ(missing, 0u);
}

// The mesh's triangles as the scan conversion uploads them: grid-local voxel units, pseudonormals,
// face_normal.w 0 for a degenerate one; `usable` receives the others.
std::vector<gpu::layout::SdfTriangle> grid_triangles(const TriangleMesh& mesh, const GridSpec& spec,
                                                     std::vector<std::uint32_t>& usable) {
  const Pseudonormals normals = compute_pseudonormals(mesh);
  auto to_vec4 = [](const Eigen::Vector3d& v, double w = 0.0) {
    return gpu::layout::vec4{static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()),
                             static_cast<float>(w)};
  };
  std::vector<gpu::layout::SdfTriangle> triangles(mesh.triangle_count());
  usable.clear();
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    Eigen::Vector3d v[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = spec.to_voxel(mesh.vertices[mesh.triangles[t][k]]);
      triangles[t].vertex[k] = to_vec4(v[k]);
      triangles[t].edge_normal[k] = to_vec4(normals.edge[t][static_cast<std::size_t>(k)]);
      triangles[t].vertex_normal[k] = to_vec4(normals.vertex[t][static_cast<std::size_t>(k)]);
    }
    const bool degenerate = !((v[1] - v[0]).cross(v[2] - v[0]).norm() > 1e-9);
    triangles[t].face_normal = to_vec4(normals.face[t], degenerate ? 0.0 : 1.0);
    if (!degenerate) usable.push_back(t);
  }
  return triangles;
}

// The pairs of one brick row as a sorted list of (triangle, brick x | brick y << 16).
std::vector<std::uint64_t> row_set(const BrickPairs& pairs, std::size_t row) {
  std::vector<std::uint64_t> out;
  for (std::uint32_t p = pairs.row_begin[row]; p < pairs.row_begin[row + 1]; ++p)
    out.push_back(std::uint64_t{pairs.words[2 * p]} << 32 | pairs.words[2 * p + 1]);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(GpuBrickPairs, AreTheHostPairsAsASetInEveryBrickRow) {
  gpu::Context context;
  const gpu::ShaderLibrary library;
  gpu::Queue queue;
  BrickPairGenerator generator(library);
  TriangleMesh cube = box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  cube.triangles.push_back({0, 0, 1});  // degenerate: no pairs on either side
  struct Case {
    const char* name;
    TriangleMesh mesh;
    int resolution;
  };
  const Case cases[] = {{"knot1", load_mesh(test::cgal_mesh("knot1")), 40},
                        {"fandisk", load_mesh(test::cgal_mesh("fandisk")), 32},
                        {"cube", cube, 24}};
  for (const Case& c : cases) {
    SdfSettings settings;
    settings.resolution = c.resolution;
    const GridSpec spec = make_grid(bounding_box(c.mesh), settings);
    std::vector<std::uint32_t> usable;
    const auto triangles = grid_triangles(c.mesh, spec, usable);
    const gpu::Buffer buffer = gpu::Buffer::from<gpu::layout::SdfTriangle>(triangles);
    for (int side : {2, 4}) {
      SCOPED_TRACE(std::string(c.name) + " brick " + std::to_string(side));
      const BrickPairs host = build_brick_pairs(triangles, usable, spec, 3.25, side);
      const BrickPairs device =
          generator.run(queue, buffer, static_cast<std::uint32_t>(triangles.size()), spec, 3.25, side).download();
      EXPECT_GT(host.count(), 1000u);
      EXPECT_EQ(device.brick, side);
      ASSERT_EQ(device.row_begin, host.row_begin);
      std::size_t different_rows = 0;
      for (std::size_t r = 0; r + 1 < host.row_begin.size(); ++r)
        different_rows += row_set(device, r) == row_set(host, r) ? 0 : 1;
      EXPECT_EQ(different_rows, 0u);
    }
  }
}

// Pairs with each row's order changed (`order`: 0 as given, 1 reversed, 2 shuffled) on the GPU.
GpuBrickPairs reorder_rows(const BrickPairs& pairs, int order) {
  std::vector<std::uint32_t> words = pairs.words;
  std::mt19937 random(7);
  for (std::size_t r = 0; r + 1 < pairs.row_begin.size(); ++r) {
    std::vector<std::uint64_t> row;
    for (std::uint32_t p = pairs.row_begin[r]; p < pairs.row_begin[r + 1]; ++p)
      row.push_back(std::uint64_t{words[2 * p]} << 32 | words[2 * p + 1]);
    if (order == 1) std::reverse(row.begin(), row.end());
    if (order == 2) std::shuffle(row.begin(), row.end(), random);
    for (std::size_t k = 0; k < row.size(); ++k) {
      words[2 * (pairs.row_begin[r] + k)] = static_cast<std::uint32_t>(row[k] >> 32);
      words[2 * (pairs.row_begin[r] + k) + 1] = static_cast<std::uint32_t>(row[k]);
    }
  }
  GpuBrickPairs out;
  out.brick = pairs.brick;
  out.row_begin = pairs.row_begin;
  out.pairs = gpu::Buffer::from<std::uint32_t>(words);
  return out;
}

TEST(GpuBrickPairs, OrderWithinARowDoesNotChangeOneBitOfTheField) {
  // The GPU's atomics hand out places within a row in whatever order invocations run; the passes
  // keep the least distance, then the least triangle index, so any order must give the same bytes.
  gpu::Context context;
  const gpu::ShaderLibrary library;
  gpu::Queue queue;
  const TriangleMesh mesh = load_mesh(test::cgal_mesh("knot1"));
  SdfSettings settings;
  settings.resolution = 24;
  const GridSpec spec = make_grid(bounding_box(mesh), settings);
  std::vector<std::uint32_t> usable;
  const auto triangles = grid_triangles(mesh, spec, usable);
  const gpu::Buffer buffer = gpu::Buffer::from<gpu::layout::SdfTriangle>(triangles);
  const BrickPairs host = build_brick_pairs(triangles, usable, spec, 3.25, 2);
  const std::size_t floats = 4 * static_cast<std::size_t>(spec.voxel_count());
  auto field = [&](GpuBrickPairs pairs) {
    const std::vector<float> clear(floats, 0.0f);
    gpu::Texture target =
        gpu::Texture::create_2d_array(GL_RGBA32F, spec.dims.x(), spec.dims.y(), spec.dims.z(), "test slab");
    target.upload(clear.data(), GL_RGBA, GL_FLOAT);
    ts::sdf::ComputeScan scan(library, std::move(pairs), spec, spec.dims.z(), 3.0);
    EXPECT_EQ(scan.fill(queue, buffer, target, 0, spec.dims.z()), host.count());
    std::vector<float> values(floats);
    target.read(values.data(), values.size() * sizeof(float), GL_RGBA, GL_FLOAT);
    return values;
  };
  const std::vector<float> ascending = field(reorder_rows(host, 0));
  std::size_t reached = 0;
  for (std::size_t v = 0; v < floats; v += 4) reached += ascending[v + 3] != 0.0f ? 1 : 0;
  EXPECT_GT(reached, 3000u);
  BrickPairGenerator generator(library);
  const std::vector<float> fields[] = {
      field(reorder_rows(host, 1)), field(reorder_rows(host, 2)),
      field(generator.run(queue, buffer, static_cast<std::uint32_t>(triangles.size()), spec, 3.25, 2))};
  for (const std::vector<float>& other : fields)
    EXPECT_EQ(std::memcmp(other.data(), ascending.data(), floats * sizeof(float)), 0);
}

TEST(BrickPairs, EveryBrickWithAVoxelInATrianglesBandIsPairedWithItAndRowsAreSorted) {
  const TriangleMesh sphere = test::icosphere(0.5, 1);
  const GridSpec spec = grid_around(sphere, 1.0 / 12.0, 4);
  const double band = 3.0;
  std::vector<gpu::layout::SdfTriangle> triangles(sphere.triangle_count());
  std::vector<std::uint32_t> usable;
  for (std::uint32_t t = 0; t < sphere.triangle_count(); ++t) {
    Eigen::Vector3d v[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = spec.to_voxel(sphere.vertices[sphere.triangles[t][k]]);
      triangles[t].vertex[k] = {static_cast<float>(v[k].x()), static_cast<float>(v[k].y()),
                                static_cast<float>(v[k].z()), 0.0f};
    }
    const Eigen::Vector3d n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
    triangles[t].face_normal = {static_cast<float>(n.x()), static_cast<float>(n.y()),
                                static_cast<float>(n.z()), 1.0f};
    usable.push_back(t);
  }
  for (int side : {2, 4}) {
    SCOPED_TRACE(side);
    expect_every_band_brick_paired(sphere, spec, triangles, usable, band, side);
  }
}

}  // namespace
}  // namespace ts::sdf
