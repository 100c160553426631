// The executable's contract: subcommands, --help, unknown options, exit codes.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include <nlohmann/json.hpp>

#include "core/mesh_io.h"
#include "core/primitives.h"
#include "tests/test_support.h"

namespace ts {
namespace {

TEST(Cli, HelpListsTheSubcommands) {
  std::string out;
  EXPECT_EQ(test::run_tetrasand("--help", &out), 0);
  EXPECT_NE(out.find("devices"), std::string::npos) << out;
}

TEST(Cli, UnknownOptionIsAUsageError) {
  std::string out;
  EXPECT_EQ(test::run_tetrasand("devices --no-such-option", &out), 2) << out;
}

TEST(Cli, MissingSubcommandIsAUsageError) { EXPECT_EQ(test::run_tetrasand(""), 2); }

TEST(Cli, DevicesNamesTheChosenRenderer) {
  std::string out;
  ASSERT_EQ(test::run_tetrasand("devices", &out), 0) << out;
  EXPECT_NE(out.find("chosen: device"), std::string::npos) << out;
}

TEST(Cli, NonexistentDeviceExitsWithGpuFailure) {
  std::string out;
  EXPECT_EQ(test::run_tetrasand("--device 99 devices", &out), 3) << out;
  EXPECT_NE(out.find("does not exist"), std::string::npos) << out;
}

}  // namespace
}  // namespace ts

namespace ts {
namespace {

TEST(CliSdf, WritesALevelSetOfTheCube) {
  const auto dir = test::temp_dir();
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sdf '" + test::asset("cube.obj").string() + "' -o '" + (dir / "cube.vdb").string() +
                                    "' --resolution 16 --timings --backend gpu",
                                &out),
            0)
      << out;
  EXPECT_TRUE(std::filesystem::exists(dir / "cube.vdb"));
  EXPECT_NE(out.find("band voxels"), std::string::npos) << out;
  EXPECT_NE(out.find("peak GPU memory"), std::string::npos) << out;
}

// --timings splits the scan conversion into GPU, read-back and host build, and times the write; --json
// carries the same figures, each non-negative, the parts of the scan within its whole.
TEST(CliSdf, TimingsSplitTheScanIntoGpuReadbackHostBuildAndWrite) {
  const auto dir = test::temp_dir();
  const std::string bunny = "'" + test::asset("bunny.obj").string() + "'";
  const std::string common = " --resolution 48 --max-slab-mb 1 --backend gpu";
  std::string out;
  ASSERT_EQ(test::run_tetrasand(
                "sdf " + bunny + " -o '" + (dir / "b.vdb").string() + "'" + common + " --timings", &out),
            0)
      << out;
  EXPECT_TRUE(std::regex_search(
      out,
      std::regex(
          R"(\ntimes: scan conversion \d+\.\d{3} s \(GPU \d+\.\d{3} s, read-back \d+\.\d{3} s, host build )"
          R"(\d+\.\d{3} s on this thread; leaves built \d+\.\d{3} s beside the GPU\), write \d+\.\d{3} s\n)")))
      << out;
  ASSERT_EQ(test::run_tetrasand(
                "sdf " + bunny + " -o '" + (dir / "b.nvdb").string() + "'" + common + " --json", &out),
            0)
      << out;
  const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
  double parts = 0.0;
  for (const char* key : {"gpu_seconds", "readback_seconds", "host_build_seconds"}) {
    ASSERT_TRUE(json.contains(key)) << key << "\n" << out;
    EXPECT_GT(json.at(key).get<double>(), 0.0) << key;
    parts += json.at(key).get<double>();
  }
  EXPECT_LE(parts, json.at("scan_seconds").get<double>());
  EXPECT_GT(json.at("leaf_build_seconds").get<double>(), 0.0);
  EXPECT_GT(json.at("write_seconds").get<double>(), 0.0);
  EXPECT_LE(json.at("scan_seconds").get<double>() + json.at("write_seconds").get<double>(),
            json.at("total_seconds").get<double>());
}

TEST(CliSdf, TimingsOnTheGeometryPathCountItsPipelineBesideThePrismModel) {
  const auto dir = test::temp_dir();
  const std::string bunny = "'" + test::asset("bunny.obj").string() + "'";
  const std::string common = " --resolution 32 --backend gpu --timings";
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sdf " + bunny + " -o '" + (dir / "g.vdb").string() + "'" + common +
                                    " --scan geometry --json",
                                &out),
            0)
      << out;
  const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
  if (json.at("pipeline").is_null()) GTEST_SKIP() << "no pipeline statistics queries here";
  const auto& p = json.at("pipeline");
  EXPECT_GT(p.at("geometry_primitives").get<double>(), 0.0);
  EXPECT_NEAR(p.at("geometry_primitives").get<double>(), p.at("model_primitives").get<double>(),
              1e-3 * p.at("model_primitives").get<double>());
  EXPECT_GE(p.at("fragments").get<double>(), json.at("band_voxels").get<double>());
  ASSERT_EQ(
      test::run_tetrasand("sdf " + bunny + " -o '" + (dir / "g.vdb").string() + "'" + common + " --scan geometry", &out),
      0)
      << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(\npipeline statistics \(geometry path\) against the prism model: )"
                                                R"(\d+ geometry-shader invocations \(\d+ asked for by \d+ prisms\), )"
                                                R"(\d+ primitives emitted \(\d+ by the model\), \d+ fragments)")))
      << out;
  // The compute path draws nothing: no counts, null in the JSON.
  ASSERT_EQ(test::run_tetrasand("sdf " + bunny + " -o '" + (dir / "c.vdb").string() + "'" + common +
                                    " --scan compute --json",
                                &out),
            0)
      << out;
  EXPECT_TRUE(nlohmann::json::parse(out.substr(out.find("{\n"))).at("pipeline").is_null()) << out;
}

TEST(CliSdf, BadParametersAndFilesExitNonZeroWithAMessage) {
  const auto dir = test::temp_dir();
  const std::string cube = test::asset("cube.obj").string();
  std::string out;
  EXPECT_EQ(test::run_tetrasand("sdf '" + cube + "' -o '" + (dir / "a.vdb").string() + "' --band 0.5", &out), 1) << out;
  EXPECT_NE(out.find("band"), std::string::npos) << out;
  EXPECT_EQ(test::run_tetrasand("sdf '" + cube + "' -o '" + (dir / "a.vdb").string() + "' --voxel -1", &out), 2) << out;
  EXPECT_EQ(test::run_tetrasand("sdf /nonexistent.obj -o '" + (dir / "a.vdb").string() + "'", &out), 1) << out;
  EXPECT_NE(out.find("no such file"), std::string::npos) << out;
  // The output may never replace the input.
  const auto copy = dir / "cube.obj";
  std::filesystem::copy_file(cube, copy);
  EXPECT_EQ(test::run_tetrasand("sdf '" + copy.string() + "' -o '" + copy.string() + "' --resolution 8", &out), 2) << out;
  EXPECT_NE(out.find("must end in .vdb"), std::string::npos) << out;
  EXPECT_EQ(std::filesystem::file_size(copy), std::filesystem::file_size(cube));
  EXPECT_FALSE(std::filesystem::exists(dir / "a.vdb"));
}

TEST(CliInfo, ReportsHolesAndMassPropertiesAsJson) {
  std::string out;
  ASSERT_EQ(test::run_tetrasand("info --json '" + test::asset("cube.obj").string() + "' --density 2000", &out), 0) << out;
  EXPECT_NE(out.find("\"watertight\": true"), std::string::npos) << out;
  EXPECT_NE(out.find("\"mass\": 2.0"), std::string::npos) << out;
  ASSERT_EQ(test::run_tetrasand("info '" + test::assimp_model("STL/sphereWithHole.stl").string() + "'", &out), 0) << out;
  EXPECT_NE(out.find("boundary edges"), std::string::npos) << out;
  EXPECT_NE(out.find("none: the mesh does not enclose a volume"), std::string::npos) << out;
}

// One up convention (+z, issue 17): info names the tallest axis and, for a mesh tallest along y, the
// --up option and the scene orientation that stand it on +z.
TEST(CliInfo, ReportsTheTallestAxisAndHowToStandTheMeshOnZ) {
  const auto dir = test::temp_dir();
  write_obj(dir / "post.obj", make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.02, 0.1, 0.03)));
  std::string out;
  ASSERT_EQ(test::run_tetrasand("info '" + (dir / "post.obj").string() + "'", &out), 0) << out;
  EXPECT_NE(
      out.find("up axis               tallest along y (0.1 m; z 0.03 m): tetrasand takes +z as up; if this "
               "mesh stands along +y"),
      std::string::npos)
      << out;
  EXPECT_NE(out.find("pass --up 0,1,0 to preview and sample"), std::string::npos) << out;
  ASSERT_EQ(test::run_tetrasand("info --json '" + (dir / "post.obj").string() + "'", &out), 0) << out;
  EXPECT_NE(out.find("\"tallest\": \"y\""), std::string::npos) << out;
  EXPECT_NE(out.find("\"ambiguous\": false"), std::string::npos) << out;
}

}  // namespace
}  // namespace ts

namespace ts {
namespace {

using test::quoted;

TEST(CliSdf, CompareOpenVdbPrintsTheThreeWayStatisticsOnARealMesh) {
  const auto dir = test::temp_dir();
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sdf " + quoted(test::cgal_mesh("knot1")) + " -o " + quoted(dir / "knot.vdb") +
                                    " --resolution 32 --compare-openvdb",
                                &out),
            0)
      << out;
  for (const char* line : {"tetrasand GPU vs exact", "OpenVDB vs exact", "tetrasand GPU vs OpenVDB", "mean", "p99",
                           "signs", "closer to exact: tetrasand GPU", "CPU exact", "OpenVDB meshToLevelSet"})
    EXPECT_NE(out.find(line), std::string::npos) << line << "\n" << out;
}

TEST(CliSdf, OpenVdbsOwnToolReadsTheOutputAsALevelSet) {
  const auto dir = test::temp_dir();
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sdf " + quoted(test::asset("cube.obj")) + " -o " + quoted(dir / "cube.vdb") +
                                    " --voxel 0.01 --band 2",
                                &out),
            0)
      << out;
  // vdb_print from Debian's libopenvdb-tools.
  FILE* pipe = ::popen(("vdb_print -l " + quoted(dir / "cube.vdb") + " 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string text;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) text.append(buffer, n);
  ASSERT_EQ(::pclose(pipe), 0) << text;
  EXPECT_NE(text.find("class: level set"), std::string::npos) << text;
  EXPECT_NE(text.find("voxel size: 0.01"), std::string::npos) << text;
  EXPECT_NE(text.find("Background value: 0.02"), std::string::npos) << text;
  EXPECT_NE(text.find("Name: surface"), std::string::npos) << text;
}

TEST(CliSdf, OpenMeshWarnsUnlessSignedByWindingNumber) {
  const auto dir = test::temp_dir();
  const std::string holed = quoted(test::cgal_mesh("elephant-with-holes"));
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sdf " + holed + " -o " + quoted(dir / "a.vdb") + " --resolution 24", &out), 0) << out;
  EXPECT_NE(out.find("not closed"), std::string::npos) << out;
  EXPECT_NE(out.find("--sign winding"), std::string::npos) << out;
  ASSERT_EQ(test::run_tetrasand("sdf " + holed + " -o " + quoted(dir / "b.vdb") + " --resolution 24 --sign winding",
                                &out),
            0)
      << out;
  EXPECT_EQ(out.find("not closed"), std::string::npos) << out;
}

TEST(CliSdf, PaddingBelowTheBandWarnsThatTheBandIsCut) {
  const auto dir = test::temp_dir();
  const std::string cube = quoted(test::asset("cube.obj"));
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sdf " + cube + " -o " + quoted(dir / "a.vdb") + " --resolution 16", &out), 0) << out;
  EXPECT_EQ(out.find("band is cut"), std::string::npos) << out;
  // 16 voxels + 2 * (ceil(3) + 1) automatic padding.
  EXPECT_NE(out.find("25 x 25 x 25"), std::string::npos) << out;
  ASSERT_EQ(test::run_tetrasand("sdf " + cube + " -o " + quoted(dir / "b.vdb") + " --resolution 16 --padding 1", &out), 0)
      << out;
  EXPECT_NE(out.find("band is cut"), std::string::npos) << out;
  EXPECT_NE(out.find("19 x 19 x 19"), std::string::npos) << out;
}

TEST(CliSdf, GridOverTheCapNamesTheLargestGridThatFits) {
  const auto dir = test::temp_dir();
  std::string out;
  EXPECT_EQ(test::run_tetrasand("sdf " + quoted(test::asset("cube.obj")) + " -o " + quoted(dir / "a.vdb") +
                                    " --resolution 6000",
                                &out),
            1)
      << out;
  EXPECT_NE(out.find("largest grid that fits"), std::string::npos) << out;
  EXPECT_NE(out.find("exceeds the cap"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.vdb"));
  EXPECT_EQ(test::run_tetrasand("sdf " + quoted(test::asset("cube.obj")) + " -o " + quoted(dir / "a.vdb") + " --voxel 0",
                                &out),
            2)
      << out;
}

}  // namespace
}  // namespace ts
