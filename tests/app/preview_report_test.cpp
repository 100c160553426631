// The JSON of `tetrasand preview --json` (app/preview_report.h).
#include "app/preview_report.h"

#include <gtest/gtest.h>


namespace ts::app {
namespace {

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
  r.passes = {{"sdf ray cast", 1, 2.0}};
  const nlohmann::ordered_json j = preview_report_json(r);
  EXPECT_EQ(j["outputs"], nlohmann::ordered_json({"a_000.png", "a_001.png"}));
  EXPECT_TRUE(j["inputs"]["particles"].is_null());
  EXPECT_TRUE(j["drawn"]["particles"].is_null());
  EXPECT_DOUBLE_EQ(j["drawn"]["colour"]["mean"].get<double>(), 0.5);
  EXPECT_EQ(j["passes"][0]["name"], "sdf ray cast");
}

}  // namespace
}  // namespace ts::app
