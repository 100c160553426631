// The executable's contract: subcommands, --help, unknown options, exit codes.
#include <gtest/gtest.h>

#include <filesystem>

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
                                    "' --resolution 16 --timings",
                                &out),
            0)
      << out;
  EXPECT_TRUE(std::filesystem::exists(dir / "cube.vdb"));
  EXPECT_NE(out.find("band voxels"), std::string::npos) << out;
  EXPECT_NE(out.find("peak GPU memory"), std::string::npos) << out;
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
  EXPECT_EQ(test::run_tetrasand("sdf '" + copy.string() + "' -o '" + copy.string() + "' --resolution 8", &out), 1) << out;
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

}  // namespace
}  // namespace ts
