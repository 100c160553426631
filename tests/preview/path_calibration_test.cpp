// --gpu-path auto (preview/path_calibration.h): the calibration is cached per renderer, driver and
// build, read back instead of run again, followed when it says the draws win, and a real calibration
// times both paths on this device. The cache's corrupt, foreign and stale entries are the shared
// cache's (gpu/path_calibration.h), checked through the scan conversion's tests (tests/sdf).
#include "preview/path_calibration.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "tests/test_support.h"

namespace ts::preview {
namespace {

class PreviewPathCalibration : public ::testing::Test {
 protected:
  static gpu::Context& context() {
    static gpu::Context c;
    return c;
  }
  std::filesystem::path cache = test::temp_dir() / "nested" / "preview_calibration.json";
  int calibrations = 0;
  gpu::PathTiming timing{1.0, 2.0};  // what the stand-in calibration reports: compute twice as fast

  GpuPathChoice choose(GpuPath requested = GpuPath::Auto) {
    return choose_gpu_path(context(), requested, cache, [this] {
      ++calibrations;
      return timing;
    });
  }
};

TEST_F(PreviewPathCalibration, AutoCalibratesOnceThenReadsTheCacheWithoutCalibrating) {
  const GpuPathChoice first = choose();
  EXPECT_EQ(calibrations, 1);
  EXPECT_EQ(first.describe(), "compute (calibrated 2x raster's speed)");
  ASSERT_TRUE(std::filesystem::exists(cache));
  const nlohmann::json file = nlohmann::json::parse(read_file(cache));
  EXPECT_EQ(file["format"], "tetrasand preview calibration 1");
  ASSERT_EQ(file["entries"].size(), 1u);
  EXPECT_EQ(file["entries"][0]["compute_seconds"], 1.0);
  EXPECT_EQ(file["entries"][0]["raster_seconds"], 2.0);
  const GpuPathChoice second = choose();
  EXPECT_EQ(calibrations, 1);
  EXPECT_EQ(second.describe(), "compute (calibrated 2x raster's speed, cached)");
}

TEST_F(PreviewPathCalibration, DrawsMeasuredFasterMakeAutoPickRaster) {
  timing = {2.0, 1.6};
  EXPECT_EQ(choose().describe(), "raster (calibrated 0.8x raster's speed)");
  EXPECT_EQ(choose().path, GpuPath::Raster);
  EXPECT_EQ(calibrations, 1);
}

TEST_F(PreviewPathCalibration, TieGoesToCompute) {
  timing = {1.5, 1.5};
  EXPECT_EQ(choose().path, GpuPath::Compute);
}

TEST_F(PreviewPathCalibration, ExplicitPathsNeitherCalibrateNorTouchTheCache) {
  EXPECT_EQ(choose(GpuPath::Raster).describe(), "raster (asked for)");
  EXPECT_EQ(choose(GpuPath::Compute).describe(), "compute (asked for)");
  EXPECT_EQ(calibrations, 0);
  EXPECT_FALSE(std::filesystem::exists(cache));
}

TEST_F(PreviewPathCalibration, CalibrationThatTimedNothingPicksComputeAndCachesNothing) {
  timing = {0.0, 1.0};
  EXPECT_EQ(choose().describe(), "compute (calibration timed nothing)");
  EXPECT_FALSE(std::filesystem::exists(cache));
}

TEST_F(PreviewPathCalibration, RealCalibrationRendersBothPathsOnThisDevice) {
  const gpu::PathTiming measured = calibrate_gpu_path(context());
  EXPECT_GT(measured.first_seconds, 0.0);
  EXPECT_GT(measured.second_seconds, 0.0);
  EXPECT_LT(measured.first_seconds, 1e299);  // both rounds ran
  EXPECT_LT(measured.second_seconds, 1e299);
}

}  // namespace
}  // namespace ts::preview
