// The JSON of `tetrasand preview --json` (app/preview_report.h): the renderers' per-pass tables read
// back into rows, and a table of another form refused rather than silently dropped.
#include "app/preview_report.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace ts::app {
namespace {

TEST(PreviewReport, PassTimesAreReadFromTheGpuAndCpuTables) {
  // The forms of gpu::Queue::timing_report and preview::CpuRenderer::timing_report.
  const std::string gpu =
      "GPU kernel                                  calls     total ms      share\n"
      "preview shadow map                              2        1.500      25.0%\n"
      "preview particles (impostors)                   2        4.500      75.0%\n"
      "total                                                    6.000\n";
  const std::vector<PassTime> passes = parse_pass_times(gpu);
  ASSERT_EQ(passes.size(), 2u);
  EXPECT_EQ(passes[1].name, "preview particles (impostors)");
  EXPECT_EQ(passes[1].calls, 2u);
  EXPECT_DOUBLE_EQ(passes[1].milliseconds, 4.5);
  const std::string cpu =
      "CPU pass                                    calls     total ms      share\n"
      "sdf ray cast                                    1       12.250     100.0%\n"
      "total                                                   12.250\n";
  ASSERT_EQ(parse_pass_times(cpu).size(), 1u);
  EXPECT_DOUBLE_EQ(parse_pass_times(cpu)[0].milliseconds, 12.25);
  EXPECT_TRUE(parse_pass_times("").empty());
}

TEST(PreviewReport, ATimingLineOfAnotherFormIsAnInternalError) {
  const std::string table = "GPU kernel calls total ms share\nshadow map 2 ms\n";
  try {
    parse_pass_times(table);
    FAIL() << "accepted a line of another form";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Internal);
    EXPECT_NE(std::string(e.what()).find("shadow map 2 ms"), std::string::npos) << e.what();
  }
}

TEST(PreviewReport, JsonListsOutputsAndLeavesWhatWasNotDrawnNull) {
  PreviewReport r;
  r.field_input = "cube.obj";
  r.outputs = {"a_000.png", "a_001.png"};
  r.width = 8;
  r.height = 6;
  r.views = 2;
  r.requested_backend = "auto";
  r.backend = "cpu";
  r.device = "the CPU (2 TBB threads)";
  r.field = "SDF 16 x 16 x 16 voxels";
  r.voxel_size = 0.01;
  r.colour_pixels = 4;
  r.colour_by = "error";
  r.colour_mean = 2.0;  // summed over the 4 pixels
  r.timing_report = "CPU pass calls total ms share\nsdf ray cast 1 2.000 100.0%\ntotal 2.000\n";
  const nlohmann::ordered_json j = preview_report_json(r);
  EXPECT_EQ(j["outputs"], nlohmann::ordered_json({"a_000.png", "a_001.png"}));
  EXPECT_TRUE(j["inputs"]["particles"].is_null());
  EXPECT_TRUE(j["drawn"]["particles"].is_null());
  EXPECT_DOUBLE_EQ(j["drawn"]["colour"]["mean"].get<double>(), 0.5);
  EXPECT_EQ(j["passes"][0]["name"], "sdf ray cast");
}

}  // namespace
}  // namespace ts::app
