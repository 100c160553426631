// Every command that writes, run against a full file system (issue 46): exit 1 naming the file and
// the reason, and the output a previous run wrote there byte for byte as it was. Before, `sdf -o
// X.vdb` replaced a good .vdb with a truncated one and exited 0 (OpenVDB's stream was never checked).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "tests/test_support.h"

namespace ts {
namespace {
namespace fs = std::filesystem;
using test::quoted;

// A small tmpfs mounted at a fresh folder for the test's lifetime; mounting needs root (CI runs as
// root), so `problem` says why when it could not be mounted.
class SmallDisk {
 public:
  explicit SmallDisk(const std::string& size) : dir_(test::temp_dir() / "disk") {
    fs::create_directories(dir_);
    if (::geteuid() != 0) {
      problem_ = "not root: mounting a small tmpfs to fill up needs root (CI runs as root)";
    } else if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, ("size=" + size).c_str()) != 0) {
      problem_ = std::string("cannot mount a tmpfs: ") + std::strerror(errno);
    } else {
      mounted_ = true;
    }
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;

  const fs::path& dir() const { return dir_; }
  const std::string& problem() const { return problem_; }

  // Writes a filler file until the file system has no byte left.
  void fill() const {
    const int fd = ::open((dir_ / "filler").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0) << std::strerror(errno);
    const std::vector<char> block(4096, 'x');
    while (::write(fd, block.data(), block.size()) > 0) {
    }
    ::write(fd, block.data(), 1);  // the last partial page, if any
    ::close(fd);
    ASSERT_EQ(std::string(std::strerror(ENOSPC)), "No space left on device");
  }
  void unfill() const { fs::remove(dir_ / "filler"); }

 private:
  fs::path dir_;
  std::string problem_;
  bool mounted_ = false;
};

// Every file under `dir` (but the filler) and its bytes.
std::map<std::string, std::string> contents(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().filename() != "filler")
      out[fs::relative(entry.path(), dir).string()] = read_file(entry.path());
  }
  return out;
}

struct Writer {
  std::string name;
  std::string first;   // the command that writes the good output (the disk has room)
  std::string second;  // the same output asked for again, differently, once the disk is full
};

std::vector<Writer> writers(const fs::path& disk) {
  const std::string cube = quoted(test::asset("cube.obj"));
  const std::string sphere = quoted(test::asset("sphere.obj"));
  const std::string scene = quoted(test::asset("scenes/two_grain_collision.toml"));
  const std::string sample = " --count 150 --probes 20000 --rounds 2 --backend cpu";
  const std::string sim = " --backend cpu --duration ";
  return {
      {"sdf .vdb", "sdf " + cube + " -o " + quoted(disk / "cube.vdb") + " --resolution 16",
       "sdf " + cube + " -o " + quoted(disk / "cube.vdb") + " --resolution 20"},
      {"sdf .nvdb", "sdf " + cube + " -o " + quoted(disk / "cube.nvdb") + " --resolution 16",
       "sdf " + cube + " -o " + quoted(disk / "cube.nvdb") + " --resolution 20"},
      {"sample", "sample " + sphere + " -o " + quoted(disk / "body") + sample,
       "sample " + sphere + " -o " + quoted(disk / "body") + sample + " --seed 7"},
      {"preview", "preview " + sphere + " -o " + quoted(disk / "s.png") + " --size 48x32 --resolution 16",
       "preview " + sphere + " -o " + quoted(disk / "s.png") + " --size 64x48 --resolution 16"},
      {"sim -o", "sim " + scene + " -o " + quoted(disk / "sim") + sim + "0.0002",
       "sim " + scene + " -o " + quoted(disk / "sim") + sim + "0.0003"},
      {"export lammps", "export lammps " + scene + " -o " + quoted(disk / "lammps"),
       "export lammps " + scene + " -o " + quoted(disk / "lammps")},
  };
}

TEST(FullDisk, EveryWriterExitsOneNamingTheFileAndKeepsThePreviousOutput) {
  const SmallDisk disk("8m");
  if (!disk.problem().empty()) GTEST_SKIP() << disk.problem();
  for (const Writer& w : writers(disk.dir())) {
    SCOPED_TRACE(w.name);
    std::string out;
    ASSERT_EQ(test::run_tetrasand(w.first, &out), 0) << out;
    const auto before = contents(disk.dir());
    ASSERT_FALSE(before.empty());
    disk.fill();
    EXPECT_EQ(test::run_tetrasand(w.second, &out), 1) << out;
    EXPECT_NE(out.find(disk.dir().string() + "/"), std::string::npos) << out;  // names the file
    EXPECT_NE(out.find("No space left on device"), std::string::npos) << out;
    disk.unfill();
    EXPECT_EQ(contents(disk.dir()), before);  // the good output, byte for byte, and nothing else
    for (const auto& entry : fs::directory_iterator(disk.dir())) fs::remove_all(entry.path());
  }
}

}  // namespace
}  // namespace ts
