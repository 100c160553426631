// GPU scan conversion against exact distance (a brute-force double-precision reference kept here, so
// these tests need nothing but the mesh): no holes in the band, error <= 1e-3 voxel, no sign errors.
#include "sdf/scan_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "core/mesh_report.h"
#include "core/primitives.h"
#include "gpu/context.h"
#include "gpu/gl.h"
#include "sdf/grid.h"
#include "sdf/pseudonormals.h"
#include "tests/test_meshes.h"

namespace ts::sdf {
namespace {

using test::box_mesh;
using test::grid_around;
using test::icosphere;

// Brute force: exact closest point (Ericson 5.1.5) over all triangles, sign by pseudonormal.
double exact_signed_distance(const TriangleMesh& mesh, const Pseudonormals& pn, const Eigen::Vector3d& p) {
  double best = 1e300, sign = 1.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Eigen::Vector3d a = mesh.vertices[mesh.triangles[t][0]], b = mesh.vertices[mesh.triangles[t][1]],
                          c = mesh.vertices[mesh.triangles[t][2]];
    const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a, bp = p - b, cp = p - c;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap), d3 = ab.dot(bp), d4 = ac.dot(bp), d5 = ab.dot(cp), d6 = ac.dot(cp);
    const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    Eigen::Vector3d q, n;
    if (d1 <= 0 && d2 <= 0) q = a, n = pn.vertex[t][0];
    else if (d3 >= 0 && d4 <= d3) q = b, n = pn.vertex[t][1];
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) q = a + ab * (d1 / (d1 - d3)), n = pn.edge[t][0];
    else if (d6 >= 0 && d5 <= d6) q = c, n = pn.vertex[t][2];
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) q = a + ac * (d2 / (d2 - d6)), n = pn.edge[t][2];
    else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) q = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), n = pn.edge[t][1];
    else {
      const double den = 1.0 / (va + vb + vc);
      q = a + ab * (vb * den) + ac * (vc * den), n = pn.face[t];
    }
    const double d = (p - q).norm();
    if (d < best) best = d, sign = (p - q).dot(n) >= 0 ? 1.0 : -1.0;
  }
  return sign * best;
}


struct Agreement {
  std::size_t band_voxels = 0, missing = 0, sign_errors = 0;
  double max_error_voxels = 0.0;
};

Agreement compare_with_exact(const TriangleMesh& mesh, const GridSpec& spec, const ScanConvertResult& r, double band) {
  const Pseudonormals pn = compute_pseudonormals(mesh);
  if (!r.grid) {
    // Dense field: band voxels are those whose |value| is below band * h.
    Agreement a;
    for (int k = 0; k < spec.dims.z(); ++k)
      for (int j = 0; j < spec.dims.y(); ++j)
        for (int i = 0; i < spec.dims.x(); ++i) {
          const double exact = exact_signed_distance(mesh, pn, spec.voxel_center(i, j, k)) / spec.voxel_size;
          const double gpu = r.dense.values[spec.linear_index(i, j, k)].w() / spec.voxel_size;
          if (std::abs(exact) < band - 1e-3) {
            ++a.band_voxels;
            if (!(std::abs(gpu) < band - 1e-6)) { ++a.missing; continue; }
            a.max_error_voxels = std::max(a.max_error_voxels, std::abs(gpu - exact));
          }
          if (std::abs(exact) > 1e-3 && (gpu < 0) != (exact < 0)) ++a.sign_errors;
        }
    return a;
  }
  auto acc = r.grid->getConstAccessor();
  Agreement a;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const double exact = exact_signed_distance(mesh, pn, spec.voxel_center(i, j, k)) / spec.voxel_size;
        const openvdb::Coord c(spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k);
        const double gpu = acc.getValue(c) / spec.voxel_size;
        if (std::abs(exact) < band - 1e-3) {
          ++a.band_voxels;
          if (!acc.isValueOn(c)) {
            ++a.missing;
            continue;
          }
          a.max_error_voxels = std::max(a.max_error_voxels, std::abs(gpu - exact));
        }
        if (std::abs(exact) > 1e-3 && (gpu < 0) != (exact < 0)) ++a.sign_errors;
      }
  return a;
}

class ScanConvert : public ::testing::Test {
 protected:
  gpu::Context context;
  ScanConvertResult run(const TriangleMesh& mesh, const GridSpec& spec, ScanConvertOptions options = {}) {
    return scan_convert(context, mesh, compute_pseudonormals(mesh), spec, options);
  }
};

TEST_F(ScanConvert, CubeBandIsCompleteAndExactToAThousandthVoxel) {
  const TriangleMesh cube = box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  const GridSpec spec = grid_around(cube, 1.0 / 20.3, 4);
  const auto result = run(cube, spec);
  const Agreement a = compare_with_exact(cube, spec, result, 3.0);
  EXPECT_GT(a.band_voxels, 1000u);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_EQ(a.sign_errors, 0u);
  EXPECT_LE(a.max_error_voxels, 1e-3);
  EXPECT_EQ(result.stats.band_voxels, a.band_voxels);
}

// Signed distance to the axis-aligned box [-r, r]^3 (exact, closed form) [same units as p].
double box_distance(const Eigen::Vector3d& p, double r) {
  const Eigen::Vector3d q = p.cwiseAbs() - Eigen::Vector3d::Constant(r);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

TEST_F(ScanConvert, TwelveTriangleCubeAt512CubedIsExact) {
  // Each triangle spans ~520 layers of a 523^3 grid: many draws and slabs per triangle. Small slabs
  // (~12 layers) keep host memory for the readback low; every voxel is checked in closed form.
  const TriangleMesh cube = box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  ASSERT_EQ(cube.triangle_count(), 12u);
  SdfSettings settings;
  settings.resolution = 512;
  const GridSpec spec = make_grid(bounding_box(cube), settings);
  ASSERT_GE(spec.dims.minCoeff(), 512);
  ScanConvertOptions options;
  options.max_slab_bytes = std::size_t{64} << 20;
  const auto result = run(cube, spec, options);
  EXPECT_GT(result.stats.slabs, 20);
  const double band = options.band;
  auto acc = result.grid->getConstAccessor();
  std::size_t band_voxels = 0, holes = 0, sign_errors = 0;
  double worst = 0.0;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const double exact = box_distance(spec.voxel_center(i, j, k), 0.5) / spec.voxel_size;
        const openvdb::Coord c(spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k);
        float value = 0.0f;
        const bool on = acc.probeValue(c, value);
        const double gpu = value / spec.voxel_size;
        if (std::abs(exact) < band - 1e-3) {
          ++band_voxels;
          if (!on) {
            ++holes;
            continue;
          }
          worst = std::max(worst, std::abs(gpu - exact));
        }
        if (std::abs(exact) > 1e-3 && (gpu < 0) != (exact < 0)) ++sign_errors;
      }
  EXPECT_GT(band_voxels, 6u * 512u * 512u * 5u);
  EXPECT_EQ(holes, 0u);
  EXPECT_EQ(sign_errors, 0u);
  EXPECT_LE(worst, 1e-3);
}

TEST_F(ScanConvert, AutomaticPaddingKeepsTheWholeBandAndZeroPaddingCutsItWithoutSignErrors) {
  // A sphere whose band would cross the border of a grid fitted tightly to its box.
  const TriangleMesh sphere = icosphere(1.0, 2);
  SdfSettings automatic;
  automatic.resolution = 20;
  SdfSettings wide = automatic, none = automatic;
  wide.padding = 10;
  none.padding = 0;
  const auto a = run(sphere, make_grid(bounding_box(sphere), automatic));
  const auto w = run(sphere, make_grid(bounding_box(sphere), wide));
  const auto n = run(sphere, make_grid(bounding_box(sphere), none));
  EXPECT_EQ(a.stats.band_voxels, w.stats.band_voxels);
  auto wa = w.grid->getConstAccessor();
  // Grid-local coordinates differ by the padding, so values agree to float rounding, not bit for bit.
  const double tolerance = 1e-4 * a.grid->voxelSize()[0];
  for (auto it = a.grid->cbeginValueOn(); it; ++it) ASSERT_NEAR(*it, wa.getValue(it.getCoord()), tolerance);
  // Without padding the band is cut at the border; what remains is the same field, with the same signs.
  EXPECT_LT(n.stats.band_voxels, a.stats.band_voxels);
  for (auto it = n.grid->cbeginValueOn(); it; ++it) ASSERT_NEAR(*it, wa.getValue(it.getCoord()), tolerance);
}

TEST_F(ScanConvert, LongTrianglesSpanningHundredsOfLayersComeOutExact) {
  // Each side triangle spans ~480 z-layers: far more slices than one geometry-shader invocation may emit.
  const TriangleMesh bar = box_mesh({-0.2, -0.2, -4.0}, {0.2, 0.2, 4.0});
  const GridSpec spec = grid_around(bar, 1.0 / 60.0, 4);
  ASSERT_GT(spec.dims.z(), 480);
  const auto result = run(bar, spec);
  const Agreement a = compare_with_exact(bar, spec, result, 3.0);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_EQ(a.sign_errors, 0u);
  EXPECT_LE(a.max_error_voxels, 1e-3);
}

// A square rod along `axis` (0: x, 2: z), side 2a, cut into `segments` rings so that no triangle is
// much longer than its width: the point-triangle distance is evaluated in float, and on triangles
// thousands of voxels long its cancellation alone reaches 1e-2 voxel, which is not what this is about.
TriangleMesh segmented_rod(int axis, double length, double a, int segments) {
  TriangleMesh m;
  const double corners[4][2] = {{-a, -a}, {a, -a}, {a, a}, {-a, a}};  // counter-clockwise seen from +axis
  for (int k = 0; k <= segments; ++k) {
    const double along = -length / 2 + length * k / segments;
    for (const auto& c : corners) {
      const Eigen::Vector3d x(along, c[0], c[1]);  // along x; the cyclic permutation turns x into z
      m.vertices.push_back(axis == 0 ? x : Eigen::Vector3d(x.y(), x.z(), x.x()));
    }
  }
  const auto v = [](int k, int i) { return static_cast<std::uint32_t>(4 * k + i % 4); };
  for (int k = 0; k < segments; ++k)
    for (int i = 0; i < 4; ++i) {
      m.triangles.push_back({v(k, i), v(k, i + 1), v(k + 1, i + 1)});
      m.triangles.push_back({v(k, i), v(k + 1, i + 1), v(k + 1, i)});
    }
  m.triangles.push_back({v(0, 0), v(0, 2), v(0, 1)});
  m.triangles.push_back({v(0, 0), v(0, 3), v(0, 2)});
  m.triangles.push_back({v(segments, 0), v(segments, 1), v(segments, 2)});
  m.triangles.push_back({v(segments, 0), v(segments, 2), v(segments, 3)});
  return m;
}

// The slab is a layered 2D array target: a grid wider than the largest 3D texture (2048 on llvmpipe)
// or taller than the most array layers is scanned all the same, in slabs of the layers the GPU allows.
// Before, a side over GL_MAX_3D_TEXTURE_SIZE was refused and a column over GL_MAX_ARRAY_TEXTURE_LAYERS
// layers failed in the driver.
TEST_F(ScanConvert, RodsLongerThanTheLargest3DTextureAndTheMostLayersComeOutExact) {
  const double h = 1.0 / 60.0;
  const auto& limits = context.limits();
  const int voxels = std::max(limits.max_3d_texture_size, limits.max_texture_layers) + 200;
  const double length = voxels * h;
  for (int axis : {0, 2}) {
    const TriangleMesh rod = segmented_rod(axis, length, 0.05, voxels / 64);
    const MeshReport report = analyze_mesh(rod);
    ASSERT_TRUE(report.watertight()) << "axis " << axis;
    const GridSpec spec = grid_around(rod, h, 4);
    if (axis == 0) {
      ASSERT_GT(spec.dims.x(), limits.max_3d_texture_size);
    } else {
      ASSERT_GT(spec.dims.z(), limits.max_texture_layers);
    }
    const auto result = run(rod, spec);
    EXPECT_LE(result.stats.layers_per_slab, limits.max_texture_layers);
    const Agreement a = compare_with_exact(rod, spec, result, 3.0);
    EXPECT_GT(a.band_voxels, static_cast<std::size_t>(voxels) * 40) << "axis " << axis;
    EXPECT_EQ(a.missing, 0u) << "axis " << axis;
    EXPECT_EQ(a.sign_errors, 0u) << "axis " << axis;
    EXPECT_LE(a.max_error_voxels, 1e-3) << "axis " << axis;
  }
}

TEST_F(ScanConvert, SphereMatchesExactDistanceAndSigns) {
  const TriangleMesh sphere = icosphere(1.0, 2);
  const GridSpec spec = grid_around(sphere, 2.0 / 16.0, 4);
  const auto result = run(sphere, spec);
  const Agreement a = compare_with_exact(sphere, spec, result, 3.0);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_EQ(a.sign_errors, 0u);
  EXPECT_LE(a.max_error_voxels, 1e-3);
  // Far inside and far outside take +-band from the flood fill.
  auto acc = result.grid->getConstAccessor();
  EXPECT_LT(acc.getValue(openvdb::Coord(0, 0, 0)), 0.0f);
}

TEST_F(ScanConvert, DenseCopyAgreesWithTheLevelSetEverywhere) {
  const TriangleMesh sphere = icosphere(1.0, 1);
  const GridSpec spec = grid_around(sphere, 2.0 / 14.0, 5);
  ScanConvertOptions options;
  options.keep_dense = true;
  const auto result = run(sphere, spec, options);
  auto acc = result.grid->getConstAccessor();
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const openvdb::Coord c(spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k);
        ASSERT_FLOAT_EQ(result.dense.values[spec.linear_index(i, j, k)].w(), acc.getValue(c)) << i << " " << j << " " << k;
      }
}

TEST_F(ScanConvert, SmallSlabsGiveTheSameFieldAsOneSlab) {
  const TriangleMesh sphere = icosphere(1.0, 1);
  const GridSpec spec = grid_around(sphere, 2.0 / 20.0, 4);
  const auto whole = run(sphere, spec);
  ScanConvertOptions small;
  small.max_slab_bytes = bytes_per_layer(spec) * 3;  // 3 layers per slab
  const auto sliced = run(sphere, spec, small);
  EXPECT_GT(sliced.stats.slabs, 5);
  EXPECT_EQ(whole.stats.slabs, 1);
  EXPECT_LE(sliced.stats.peak_gpu_bytes, whole.stats.peak_gpu_bytes);
  EXPECT_EQ(whole.stats.band_voxels, sliced.stats.band_voxels);
  auto a = whole.grid->getConstAccessor(), b = sliced.grid->getConstAccessor();
  for (auto it = whole.grid->cbeginValueOn(); it; ++it) ASSERT_EQ(*it, b.getValue(it.getCoord()));
  (void)a;
}

// A slab of more voxels than one row of work groups covers (256 x GL_MAX_COMPUTE_WORK_GROUP_COUNT[0],
// 16.7M on llvmpipe): its band compaction and scan go out as a 2D grid of groups (gpu::Queue), and
// the band is the one small slabs give, voxel for voxel. Until 2026-12-06 slabs were cut to one row
// (and before that came out nearly empty: a GL error, no message).
TEST_F(ScanConvert, SlabsLargerThanOneRowOfWorkGroupsGiveTheSmallSlabsBand) {
  const std::size_t row = 256u * static_cast<std::size_t>(context.limits().max_compute_work_group_count[0]);
  if (row > (std::size_t{1} << 26)) GTEST_SKIP() << "this GPU's row of " << row << " items is too large to pass here";
  // A flattened sphere: fewer layers than one draw holds, so the budget below makes the whole grid
  // one slab, of more voxels than one row.
  TriangleMesh disc = icosphere(1.0, 2);
  for (auto& v : disc.vertices) v.z() *= 0.25;
  const GridSpec spec = grid_around(disc, 2.0 / 410.0, 4);
  ASSERT_GT(spec.voxel_count(), row);
  ScanConvertOptions whole_grid;
  whole_grid.max_slab_bytes = bytes_per_layer(spec) * static_cast<std::size_t>(spec.dims.z());
  const auto whole = run(disc, spec, whole_grid);
  EXPECT_EQ(whole.stats.slabs, 1);
  ScanConvertOptions small;
  small.max_slab_bytes = bytes_per_layer(spec) * 16;
  const auto sliced = run(disc, spec, small);
  EXPECT_GT(sliced.stats.slabs, 5);
  EXPECT_GT(whole.stats.band_voxels, 6u * 400u * 400u);
  EXPECT_EQ(whole.stats.band_voxels, sliced.stats.band_voxels);
  auto b = sliced.grid->getConstAccessor();
  for (auto it = whole.grid->cbeginValueOn(); it; ++it) ASSERT_EQ(*it, b.getValue(it.getCoord())) << it.getCoord();
}

TEST_F(ScanConvert, ErrorInVoxelsIsTheSameAtTinyAndHugeScaleFarFromOrigin) {
  for (double scale : {1e-4, 1e4}) {
    TriangleMesh sphere = icosphere(scale, 1);
    for (auto& v : sphere.vertices) v += Eigen::Vector3d(3e4 * scale, -2e4 * scale, 1e4 * scale);
    const GridSpec spec = grid_around(sphere, 2.0 * scale / 16.0, 4);
    // 1e-4 m at 16 voxels is below OpenVDB's smallest voxel: check the dense field the sampler uses.
    ScanConvertOptions options;
    options.keep_dense = true;
    options.build_grid = spec.voxel_size >= kMinVdbVoxelSize;
    const auto result = run(sphere, spec, options);
    const Agreement a = compare_with_exact(sphere, spec, result, 3.0);
    EXPECT_EQ(a.missing, 0u) << scale;
    EXPECT_EQ(a.sign_errors, 0u) << scale;
    EXPECT_LE(a.max_error_voxels, 1e-3) << scale;
  }
}

TEST_F(ScanConvert, DegenerateAndNeedleTrianglesLeaveNoHolesOrNaN) {
  TriangleMesh cube = box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
  // A zero-area triangle on a face and a sliver split of another face's triangle.
  cube.triangles.push_back({0, 0, 1});
  const Eigen::Vector3d p = cube.vertices[1] + 1e-6 * (cube.vertices[3] - cube.vertices[1]);
  cube.vertices.push_back(p);
  const GridSpec spec = grid_around(cube, 1.0 / 16.0, 4);
  const auto result = run(cube, spec);
  EXPECT_EQ(result.stats.degenerate_triangles, 1u);
  for (auto it = result.grid->cbeginValueOn(); it; ++it) ASSERT_TRUE(std::isfinite(*it));
  const Agreement a = compare_with_exact(box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}), spec, result, 3.0);
  EXPECT_EQ(a.missing, 0u);
  EXPECT_EQ(a.sign_errors, 0u);
  EXPECT_LE(a.max_error_voxels, 1e-3);
}

TEST_F(ScanConvert, SheetAndNeedleThinnerThanAVoxelAreExactWithNoSignErrors) {
  const double h = 1.0 / 20.0;
  // A closed plate a tenth of a voxel thick, and a closed ring whose tube is a fifth of a voxel across.
  const TriangleMesh sheet = make_plate(0.8, 0.6, 0.1 * h, 4, 3);
  const TriangleMesh needle = make_torus(0.4, 0.1 * h, 48, 6);
  for (const TriangleMesh* mesh : {&sheet, &needle}) {
    const GridSpec spec = grid_around(*mesh, h, 4);
    const auto result = run(*mesh, spec);
    const Agreement a = compare_with_exact(*mesh, spec, result, 3.0);
    EXPECT_GT(a.band_voxels, 1000u);
    EXPECT_EQ(a.missing, 0u);
    EXPECT_EQ(a.sign_errors, 0u);
    EXPECT_LE(a.max_error_voxels, 1e-3);
  }
}

TEST_F(ScanConvert, NeedleTriangleIsCoveredByItsRectanglePrism) {
  // A single sliver (angle ~0.006 degrees at one corner) as an open mesh: unsigned distance must be exact.
  TriangleMesh needle;
  needle.vertices = {{-1.0, 0.0, 0.1}, {1.0, 0.0, -0.1}, {1.0, 0.0002, -0.1}};
  needle.triangles = {{0, 1, 2}};
  const GridSpec spec = grid_around(needle, 1.0 / 16.0, 4);
  const auto result = run(needle, spec);
  EXPECT_EQ(result.stats.needle_triangles, 1u);
  const Pseudonormals pn = compute_pseudonormals(needle);
  auto acc = result.grid->getConstAccessor();
  std::size_t missing = 0;
  double worst = 0.0;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const double exact = std::abs(exact_signed_distance(needle, pn, spec.voxel_center(i, j, k))) / spec.voxel_size;
        if (exact >= 2.999) continue;
        const openvdb::Coord c(spec.index_offset.x() + i, spec.index_offset.y() + j, spec.index_offset.z() + k);
        if (!acc.isValueOn(c)) { ++missing; continue; }
        worst = std::max(worst, std::abs(std::abs(acc.getValue(c)) / spec.voxel_size - exact));
      }
  EXPECT_EQ(missing, 0u);
  EXPECT_LE(worst, 1e-3);
}

// The programs are linked once per context: a second scan in the same process (sample --batch, the
// benches) links none, and its field is the first one's, bit for bit.
TEST_F(ScanConvert, ASecondScanInTheSameContextLinksNoProgramAndGivesTheSameField) {
  const TriangleMesh sphere = icosphere(1.0, 2);
  const GridSpec spec = grid_around(sphere, 2.0 / 24.0, 4);
  const std::size_t before = gpu::program_links();
  const auto first = run(sphere, spec);
  EXPECT_GT(gpu::program_links(), before);
  const std::size_t after_first = gpu::program_links();
  const auto second = run(sphere, spec);
  EXPECT_EQ(gpu::program_links(), after_first);
  ASSERT_EQ(first.grid->activeVoxelCount(), second.grid->activeVoxelCount());
  auto b = second.grid->getConstAccessor();
  for (auto it = first.grid->cbeginValueAll(); it; ++it) {
    ASSERT_EQ(*it, b.getValue(it.getCoord())) << it.getCoord();
    ASSERT_EQ(it.isValueOn(), b.isValueOn(it.getCoord())) << it.getCoord();
  }
}

}  // namespace
}  // namespace ts::sdf
