// The executable's contract: subcommands, --help, unknown options, exit codes.
#include <gtest/gtest.h>

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
