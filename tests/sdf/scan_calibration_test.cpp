// --scan auto (sdf/scan_calibration.h): the calibration is cached per renderer and driver, read back
// instead of run again, followed when it says geometry wins, and a corrupt or foreign cache is ignored.
#include "sdf/scan_calibration.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "gpu/context.h"
#include "tests/test_support.h"

namespace ts::sdf {
namespace {

class ScanCalibration : public ::testing::Test {
 protected:
  gpu::Context context;
  std::filesystem::path cache = test::temp_dir() / "nested" / "scan_calibration.json";
  int calibrations = 0;
  ScanTiming timing{1.0, 2.0};  // what the stand-in calibration reports: compute twice as fast

  ScanChoice choose(std::string_view requested = "auto") {
    return choose_scan(context, requested, cache, [this] {
      ++calibrations;
      return timing;
    });
  }
  void write_cache(const nlohmann::json& entries) {
    std::filesystem::create_directories(cache.parent_path());
    write_file_atomically(
        cache, nlohmann::json{{"format", "tetrasand scan calibration 1"}, {"entries", entries}}.dump());
  }
  nlohmann::json entry(std::string renderer, std::string version, double compute, double geometry,
                       std::string build = scan_build_id()) const {
    return {{"renderer", renderer},
            {"version", version},
            {"build", build},
            {"compute_seconds", compute},
            {"geometry_seconds", geometry}};
  }
};

TEST_F(ScanCalibration, AutoCalibratesOnceThenReadsTheCacheWithoutCalibrating) {
  const ScanChoice first = choose();
  EXPECT_EQ(calibrations, 1);
  EXPECT_EQ(first.method, ScanMethod::Compute);
  EXPECT_EQ(first.describe(), "scan compute (calibrated 2x geometry's speed)");
  ASSERT_TRUE(std::filesystem::exists(cache));
  const std::string written = read_file(cache);
  const ScanChoice second = choose();
  EXPECT_EQ(calibrations, 1);
  EXPECT_EQ(second.method, ScanMethod::Compute);
  EXPECT_EQ(second.describe(), "scan compute (calibrated 2x geometry's speed, cached)");
  EXPECT_EQ(read_file(cache), written);  // a cache hit rewrites nothing
}

TEST_F(ScanCalibration, CacheSayingGeometryIsFasterMakesAutoPickGeometry) {
  write_cache(nlohmann::json::array({entry(context.renderer(), context.version(), 2.0, 1.6)}));
  const ScanChoice choice = choose();
  EXPECT_EQ(calibrations, 0);
  EXPECT_EQ(choice.method, ScanMethod::Geometry);
  EXPECT_EQ(choice.describe(), "scan geometry (calibrated 0.8x geometry's speed, cached)");
}

TEST_F(ScanCalibration, CorruptCacheIsIgnoredWithAWarningAndReplaced) {
  std::filesystem::create_directories(cache.parent_path());
  std::ofstream(cache) << "{\"format\": \"tetrasand scan calib";  // cut short
  testing::internal::CaptureStderr();
  const ScanChoice choice = choose();
  const std::string warnings = testing::internal::GetCapturedStderr();
  EXPECT_NE(warnings.find("unreadable scan calibration cache"), std::string::npos) << warnings;
  EXPECT_EQ(calibrations, 1);
  EXPECT_EQ(choice.method, ScanMethod::Compute);
  choose();
  EXPECT_EQ(calibrations, 1);  // the replaced cache is read
}

TEST_F(ScanCalibration, EntryOfAnotherRendererOrDriverIsNotUsedButKept) {
  write_cache(nlohmann::json::array({entry("Some Other GPU/PCIe/SSE2", context.version(), 2.0, 1.0),
                                     entry(context.renderer(), "0.0 (Core Profile) Mesa 1.0", 2.0, 1.0)}));
  timing = {1.0, 1.0};
  const ScanChoice choice = choose();
  EXPECT_EQ(calibrations, 1);
  EXPECT_EQ(choice.method, ScanMethod::Compute);  // compute wins a tie
  const nlohmann::json file = nlohmann::json::parse(read_file(cache));
  EXPECT_EQ(file["entries"].size(), 3u);
}

TEST_F(ScanCalibration, EntryOfAnotherBuildIsNotUsedButKept) {
  // A rebuilt tetrasand may scan at other speeds: it times its own. The other build's entry stays, as
  // two executables (the tool and a test program) may share the cache and would otherwise evict each
  // other's entry on every run.
  ASSERT_NE(scan_build_id(), "unknown");
  write_cache(
      nlohmann::json::array({entry(context.renderer(), context.version(), 2.0, 1.0, "1 bytes, written 0")}));
  const ScanChoice choice = choose();
  EXPECT_EQ(calibrations, 1);
  EXPECT_EQ(choice.method, ScanMethod::Compute);
  const nlohmann::json file = nlohmann::json::parse(read_file(cache));
  ASSERT_EQ(file["entries"].size(), 2u);
  EXPECT_EQ(file["entries"][0]["build"], "1 bytes, written 0");
  EXPECT_EQ(file["entries"][1]["build"], scan_build_id());
  choose();
  EXPECT_EQ(calibrations, 1);
}

TEST_F(ScanCalibration, ADeviceKeepsItsNewestFourBuildsAndEveryOtherDevice) {
  nlohmann::json entries = nlohmann::json::array();
  for (int i = 0; i < 5; ++i)
    entries.push_back(entry(context.renderer(), context.version(), 2.0, 1.0, "build " + std::to_string(i)));
  entries.push_back(entry("Some Other GPU/PCIe/SSE2", context.version(), 2.0, 1.0, "build 0"));
  write_cache(entries);
  choose();
  EXPECT_EQ(calibrations, 1);
  const nlohmann::json kept = nlohmann::json::parse(read_file(cache))["entries"];
  ASSERT_EQ(kept.size(), 5u);  // builds 2, 3, 4 of this device, the other device's, and this build's
  EXPECT_EQ(kept[0]["build"], "build 2");
  EXPECT_EQ(kept[2]["build"], "build 4");
  EXPECT_EQ(kept[3]["renderer"], "Some Other GPU/PCIe/SSE2");
  EXPECT_EQ(kept[4]["build"], scan_build_id());
}

TEST_F(ScanCalibration, ExplicitMethodsNeitherCalibrateNorTouchTheCache) {
  EXPECT_EQ(choose("geometry").describe(), "scan geometry (--scan)");
  EXPECT_EQ(choose("compute").describe(), "scan compute (--scan)");
  EXPECT_EQ(calibrations, 0);
  EXPECT_FALSE(std::filesystem::exists(cache));
}

TEST_F(ScanCalibration, RealCalibrationTimesBothPathsInSecondsAtMost) {
  const ScanTiming measured = calibrate_scan(context);
  EXPECT_GT(measured.compute_seconds, 0.0);
  EXPECT_GT(measured.geometry_seconds, 0.0);
  EXPECT_LT(measured.compute_seconds + measured.geometry_seconds, 20.0);  // llvmpipe on a loaded machine
}

}  // namespace
}  // namespace ts::sdf
