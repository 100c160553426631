#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "tests/test_support.h"

namespace ts {
namespace {

TEST(AtomicFile, WritesContentsAndLeavesNoTemporaryBehind) {
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "out.txt", "hello");
  EXPECT_EQ(read_file(dir / "out.txt"), "hello");
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u);
}

TEST(AtomicFile, FailedWriteKeepsThePreviousFileWhole) {
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "out.txt", "old contents");
  EXPECT_THROW(write_atomically(dir / "out.txt",
                                [](const std::filesystem::path& tmp) {
                                  std::ofstream(tmp) << "partial";
                                  throw InputError("simulated failure halfway");
                                }),
               InputError);
  EXPECT_EQ(read_file(dir / "out.txt"), "old contents");
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u);
}

TEST(AtomicFile, RefusesToOverwriteAnInput) {
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "mesh.obj", "v 0 0 0\n");
  EXPECT_THROW(write_file_atomically(dir / "mesh.obj", "x", {dir / "mesh.obj"}), InputError);
  EXPECT_EQ(read_file(dir / "mesh.obj"), "v 0 0 0\n");
}

TEST(AtomicFile, ReadingMissingFileOrDirectoryNamesThePath) {
  const auto dir = test::temp_dir();
  try {
    read_file(dir / "missing.obj");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.obj: no such file"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_file(dir), InputError);
}

TEST(AtomicFile, Sha256OfKnownBytes) {
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "abc", "abc");
  EXPECT_EQ(sha256_file(dir / "abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

}  // namespace
}  // namespace ts
