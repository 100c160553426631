// Signs outside the narrow band by connectivity: the grid border region is outside, enclosed regions
// inside, cavities (hollows of shells) outside.
#include "sdf/inside_outside.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sdf/exact_sdf.h"
#include "tests/test_meshes.h"

namespace ts::sdf {
namespace {

// The dense band of an analytic field: d(p) where |d| < band_world, kNotInBand elsewhere.
template <class Distance>
std::vector<float> analytic_band(const GridSpec& spec, float band_world, Distance&& distance) {
  std::vector<float> values(spec.voxel_count(), kNotInBand);
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const double d = distance(spec.voxel_center(i, j, k));
        if (std::abs(d) < band_world) values[spec.linear_index(i, j, k)] = static_cast<float>(d);
      }
  return values;
}

GridSpec cube_grid(int n, double h) {
  GridSpec spec;
  spec.voxel_size = h;
  spec.dims = Eigen::Vector3i::Constant(n);
  spec.index_offset = Eigen::Vector3i::Constant(-n / 2);
  spec.origin = h * spec.index_offset.cast<double>();
  return spec;
}

double box_distance(const Eigen::Vector3d& p, double half) {
  const Eigen::Vector3d q = p.cwiseAbs() - Eigen::Vector3d::Constant(half);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

TEST(InsideOutside, BoxInteriorIsNegativeAndTheRestPositive) {
  const GridSpec spec = cube_grid(24, 0.1);
  const float band = 1.0f * 0.1f;
  const double half = 0.65;
  std::vector<float> values = analytic_band(spec, band, [&](const Eigen::Vector3d& p) { return box_distance(p, half); });
  const std::vector<float> band_values = values;
  const InsideOutsideStats stats = fill_outside_band_signs(spec, values, band);
  EXPECT_EQ(stats.regions, 2u);
  EXPECT_EQ(stats.cavities, 0u);
  EXPECT_GT(stats.inside_voxels, 500u);
  std::size_t checked = 0;
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        const std::size_t v = spec.linear_index(i, j, k);
        ASSERT_TRUE(std::isfinite(values[v]));
        if (std::isfinite(band_values[v])) {
          EXPECT_EQ(values[v], band_values[v]);  // band untouched
          continue;
        }
        const double d = box_distance(spec.voxel_center(i, j, k), half);
        EXPECT_EQ(values[v], d < 0 ? -band : band) << i << " " << j << " " << k;
        ++checked;
      }
  EXPECT_EQ(checked, stats.inside_voxels + stats.outside_voxels);
}

TEST(InsideOutside, HollowShellCavityIsOutside) {
  // A spherical shell between radii 0.4 and 0.9: the ball inside 0.4 is enclosed but not solid.
  const GridSpec spec = cube_grid(28, 0.1);
  const float band = 0.15f;
  std::vector<float> values = analytic_band(spec, band, [](const Eigen::Vector3d& p) {
    return std::max(p.norm() - 0.9, 0.4 - p.norm());
  });
  const InsideOutsideStats stats = fill_outside_band_signs(spec, values, band);
  EXPECT_EQ(stats.regions, 3u);
  EXPECT_EQ(stats.cavities, 1u);
  EXPECT_EQ(values[spec.linear_index(14, 14, 14)], band);     // the centre: in the cavity
  EXPECT_EQ(values[spec.linear_index(14 + 6, 14, 14)], -band);  // radius 0.6: in the shell
  EXPECT_EQ(values[spec.linear_index(0, 0, 0)], band);
}

TEST(InsideOutside, ExactBandOfASphereFillsLikeTheFloodFilledGrid) {
  const TriangleMesh sphere = test::icosphere(0.5, 2);
  SdfSettings settings;
  settings.resolution = 16;
  const GridSpec spec = make_grid(bounding_box(sphere), settings);
  const double band_voxels = 1.5;
  const auto band_world = static_cast<float>(band_voxels * spec.voxel_size);
  std::vector<float> dense = exact_sdf_dense(sphere, spec, band_voxels, SignMethod::Pseudonormal);
  const std::vector<float> expected = dense;
  for (float& v : dense)
    if (std::abs(v) >= band_world) v = kNotInBand;
  fill_outside_band_signs(spec, dense, band_world);
  for (std::size_t v = 0; v < dense.size(); ++v) ASSERT_EQ(dense[v], expected[v]) << v;
}

TEST(InsideOutside, GridWithoutBandIsAllOutside) {
  const GridSpec spec = cube_grid(5, 1.0);
  std::vector<float> values(spec.voxel_count(), kNotInBand);
  const InsideOutsideStats stats = fill_outside_band_signs(spec, values, 3.0f);
  EXPECT_EQ(stats.regions, 1u);
  EXPECT_EQ(stats.outside_voxels, spec.voxel_count());
  for (float v : values) EXPECT_EQ(v, 3.0f);
}

}  // namespace
}  // namespace ts::sdf
