#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "core/checked_output.h"
#include "core/error.h"
#include "core/temporary_name.h"
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

TEST(AtomicFile, AFailedWriteIsSeenEvenWhenTheWriterIgnoresTheStream) {
  // /dev/full fails every write with ENOSPC, as a full disk does.
  const int fd = ::open("/dev/full", O_WRONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  CheckedFileBuf buf(fd);
  std::ostream out(&buf);
  out << std::string(100000, 'x');  // past the buffer: written at once
  out << "and a little more";
  EXPECT_FALSE(buf.drain());
  EXPECT_EQ(buf.error(), ENOSPC);
  ::close(fd);
}

TEST(AtomicFile, SeeksOfTheCheckedStreamLandWhereAFileStreamsWould) {
  // OpenVDB and NanoVDB go back to write offsets: seekp relative and absolute, then on to the end.
  const auto dir = test::temp_dir();
  write_stream_atomically(dir / "f", [](std::ostream& out) {
    out << "0123456789";
    const auto end = out.tellp();
    out.seekp(2);
    out << "ab";
    out.seekp(3, std::ios_base::cur);
    out << "c";
    out.seekp(end);
    out << "!";
  });
  EXPECT_EQ(read_file(dir / "f"), "01ab456c89!");
}

TEST(AtomicFile, AStreamWriterThatThrowsLeavesThePreviousFileAndNoTemporary) {
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "out.txt", "old contents");
  EXPECT_THROW(write_stream_atomically(dir / "out.txt",
                                       [](std::ostream& out) {
                                         out << "partial";
                                         throw InputError("simulated failure halfway");
                                       }),
               InputError);
  EXPECT_EQ(read_file(dir / "out.txt"), "old contents");
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u);
}

TEST(TemporaryName, OnlyTheExactSpellingParsesAndNoNameThrows) {
  const TemporaryName ours{"metrics.csv", 1234, 5678, 0xfedcba9876543210};
  const std::string name = format_temporary_name(ours);
  EXPECT_EQ(name, ".metrics.csv.tetrasand-tmp.1234.5678.fedcba9876543210");
  const auto parsed = parse_temporary_name(name);
  ASSERT_TRUE(parsed.has_value());
  EXPECT_EQ(parsed->target, "metrics.csv");
  EXPECT_EQ(parsed->pid, 1234);
  EXPECT_EQ(parsed->start, 5678u);
  EXPECT_EQ(parsed->id, 0xfedcba9876543210u);
  for (const std::string bad : {
           ".metrics.csv.tmp.1234.7",                                             // the old pattern
           ".metrics.csv.tetrasand-tmp.12345678901234567890.0.0123456789abcdef",  // 20 digits
           ".metrics.csv.tetrasand-tmp.99999999999.0.0123456789abcdef",           // not a process id
           ".metrics.csv.tetrasand-tmp.0.0.0123456789abcdef",
           ".metrics.csv.tetrasand-tmp.-1.0.0123456789abcdef",
           ".metrics.csv.tetrasand-tmp.+1.0.0123456789abcdef",
           ".metrics.csv.tetrasand-tmp.01.0.0123456789abcdef",
           ".metrics.csv.tetrasand-tmp.1.0.0123456789ABCDEF",
           ".metrics.csv.tetrasand-tmp.1.0.0123456789abcde",
           ".metrics.csv.tetrasand-tmp.1.0.0123456789abcdef0",
           ".metrics.csv.tetrasand-tmp.1.99999999999999999999999.0123456789abcdef",
           ".metrics.csv.tetrasand-tmp.1..0123456789abcdef",
           ".metrics.csv.tetrasand-tmp.1.0.",
           ".metrics.csv.tetrasand-tmp.",
           "metrics.csv.tetrasand-tmp.1.0.0123456789abcdef",
           "..tetrasand-tmp.1.0.0123456789abcdef",
           "",
       }) {
    EXPECT_FALSE(parse_temporary_name(bad).has_value()) << bad;
  }
}

TEST(TemporaryName, CleanUpRemovesOnlyExactNamesOfWritersThatAreGone) {
  const auto dir = test::temp_dir();
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const std::string gone = format_temporary_name({"a.csv", dead, 0, 1});
  // The parent's process id with another start time: an id taken over by a new process.
  const std::string reused = format_temporary_name({"a.csv", ::getppid(), 1, 2});
  const std::string live = format_temporary_name({"a.csv", ::getppid(), process_start_time(::getppid()), 3});
  const std::string mine = format_temporary_name(temporary_name_for("a.csv"));
  const std::string users = ".a.csv.tmp." + std::to_string(dead) + ".4";
  const std::string other_target = format_temporary_name({"b.csv", dead, 0, 5});
  for (const std::string& name : {gone, reused, live, mine, users, other_target})
    write_file_atomically(dir / name, "x");
  std::filesystem::create_directory(dir / format_temporary_name({"a.csv", dead, 0, 6}));  // not a file

  remove_dead_temporaries(dir, "a.csv");
  EXPECT_FALSE(std::filesystem::exists(dir / gone));
  EXPECT_EQ(std::filesystem::exists(dir / reused), process_start_time(::getppid()) == 0);
  for (const std::string& name : {live, mine, users, other_target})
    EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;
  EXPECT_TRUE(std::filesystem::is_directory(dir / format_temporary_name({"a.csv", dead, 0, 6})));
  remove_dead_temporaries(dir);
  EXPECT_FALSE(std::filesystem::exists(dir / other_target));
  EXPECT_TRUE(std::filesystem::exists(dir / users));
}

}  // namespace
}  // namespace ts
