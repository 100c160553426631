#include "sdf/grid.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace ts::sdf {
namespace {

Aabb unit_box() {
  Aabb box;
  box.extend({-0.5, -0.25, 0.0});
  box.extend({0.5, 0.25, 0.1});
  return box;
}

TEST(MakeGrid, AlignsWithOpenVdbIndexSpaceAndPadsTheBox) {
  SdfSettings s;
  s.resolution = 40;
  const GridSpec spec = make_grid(unit_box(), s);
  EXPECT_DOUBLE_EQ(spec.voxel_size, 1.0 / 40);
  EXPECT_EQ(spec.origin, spec.voxel_size * spec.index_offset.cast<double>());
  // Default padding ceil(band) + 1 = 4 voxels beyond the box on every side.
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(spec.voxel_center(0, 0, 0)[a], unit_box().min[a] - 4 * spec.voxel_size + 1e-12);
    const Eigen::Vector3d far = spec.voxel_center(spec.dims.x() - 1, spec.dims.y() - 1, spec.dims.z() - 1);
    EXPECT_GE(far[a], unit_box().max[a] + 4 * spec.voxel_size - 1e-12);
  }
}

TEST(MakeGrid, RejectsBadSettingsWithClearMessages) {
  SdfSettings s;
  s.voxel_size = -1.0;
  EXPECT_THROW(make_grid(unit_box(), s), InputError);
  s = {};
  s.band = 0.5;
  EXPECT_THROW(make_grid(unit_box(), s), InputError);
  s = {};
  s.resolution = 0;
  EXPECT_THROW(make_grid(unit_box(), s), InputError);
  EXPECT_THROW(make_grid(Aabb{}, SdfSettings{}), InputError);
}

TEST(MakeGrid, GridAboveTheCapNamesTheSmallestVoxelThatFits) {
  SdfSettings s;
  s.voxel_size = 1e-4;
  s.max_voxels = 1'000'000;
  try {
    make_grid(unit_box(), s);
    FAIL();
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("smallest voxel size that fits"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace ts::sdf
