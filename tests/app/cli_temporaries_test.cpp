// `sim -o DIR` clears away what a killed run left in DIR, and nothing else (issue 46): before, any
// file named like ".NAME.tmp.N.N" whose N was not a live process was deleted, and a 20-digit N made
// the run fail with exit 5 (std::stol).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <set>
#include <string>

#include "core/atomic_file.h"
#include "core/temporary_name.h"
#include "tests/test_support.h"

namespace ts {
namespace {
namespace fs = std::filesystem;
using test::quoted;

// A process id that was in use and is free now.
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

std::set<std::string> names_in(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename().string());
  return names;
}

TEST(Temporaries, AUsersLookAlikeFilesSurviveASimRunAndADeadRunsOwnAreRemoved) {
  const fs::path dir = test::temp_dir() / "out";
  fs::create_directories(dir);
  const pid_t dead = dead_pid();
  const std::set<std::string> users = {
      ".notes.tmp." + std::to_string(dead) + ".1",  // the old pattern, a free process id
      ".metrics.csv.tmp.12345678901234567890.1",    // 20 digits: std::stol threw (exit 5)
      ".metrics.csv.tetrasand-tmp.12345678901234567890.0.0123456789abcdef",
      ".metrics.csv.tetrasand-tmp." + std::to_string(dead) + ".0.0123456789ABCDEF",  // not our spelling
      ".metrics.csv.tetrasand-tmp." + std::to_string(dead) + ".00.0123456789abcdef",
      ".metrics.csv.tetrasand-tmp." + std::to_string(dead) + ".0.0123456789abcdef.bak",
      "metrics.csv.tetrasand-tmp." + std::to_string(dead) + ".0.0123456789abcdef",  // not hidden
  };
  for (const std::string& name : users) write_file_atomically(dir / name, "a user's file\n");
  // What a killed tetrasand run left: its exact name, its writer gone.
  const std::string left = format_temporary_name({"metrics.csv", dead, 0, 0x42});
  write_file_atomically(dir / left, "half a file");

  std::string out;
  ASSERT_EQ(test::run_tetrasand("sim " + quoted(test::asset("scenes/two_grain_collision.toml")) + " -o " +
                                    quoted(dir) + " --backend cpu --duration 0.0002",
                                &out),
            0)
      << out;
  const std::set<std::string> after = names_in(dir);
  for (const std::string& name : users) {
    EXPECT_TRUE(after.contains(name)) << name << " was removed";
    EXPECT_EQ(read_file(dir / name), "a user's file\n") << name;
  }
  EXPECT_FALSE(after.contains(left));
  for (const std::string& name : after) {
    EXPECT_TRUE(users.contains(name) || !name.starts_with(".")) << name << " was left behind";
  }
}

}  // namespace
}  // namespace ts
