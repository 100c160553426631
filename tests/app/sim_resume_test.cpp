// `tetrasand sim SCENE --resume DIR` after SIGKILL: a run killed at random moments (during steps,
// outputs or checkpoint writes) and resumed until it finishes writes the same bytes as a run that was
// never killed, on the CPU reference and on the GPU pipeline.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "core/atomic_file.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

extern char** environ;

namespace ts {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Grains poured into a box with a keyframed plate sweeping through and contact springs: every part
// of the state a checkpoint keeps changes as the run goes. Checkpoints every 50 steps.
std::string scene_text() {
  test::PouredScene p;
  p.pour_count = 30;
  p.pour_rate = 60.0;
  p.plate_time = 0.6;
  p.plate_x = -0.02;
  p.boundaries = R"([[boundary]]
type = "box"
min = [-0.05, -0.05, 0.0]
max = [0.05, 0.05, 0.3]
material = "sand"
)";
  p.duration = 0.6;
  p.every = 200;
  p.checkpoint_every = 50;
  return test::poured_scene(p);
}

// Starts `tetrasand ARGS...` with its output discarded; returns its pid.
pid_t spawn(const std::vector<std::string>& args) {
  std::vector<std::string> all{TETRASAND_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  EXPECT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

// Runs to the end, or kills it with SIGKILL after `kill_after` (s; < 0: never). Returns the exit
// code, or -1 when it was killed.
int run(const std::vector<std::string>& args, double kill_after) {
  const pid_t pid = spawn(args);
  int status = 0;
  if (kill_after >= 0) {
    const auto deadline = Clock::now() + std::chrono::duration<double>(kill_after);
    while (Clock::now() < deadline) {
      if (waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    kill(pid, SIGKILL);
  }
  waitpid(pid, &status, 0);
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

std::map<std::string, std::string> outputs(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.ends_with(".tsck") || name.starts_with(".")) continue;
    files[name] = read_file(e.path());
  }
  return files;
}

// Kills a run at `trials` x 2 random moments (the fresh run, then its first resume) and resumes it
// until it ends; each time the folder's outputs are the uninterrupted run's, byte for byte.
void expect_killed_runs_end_the_same(const std::vector<std::string>& engine, int trials, unsigned seed) {
  const fs::path dir = test::temp_dir();
  write_file_atomically(dir / "scene.toml", scene_text());
  const std::string scene = (dir / "scene.toml").string();
  std::vector<std::string> plain{"sim", scene, "-o", (dir / "plain").string()};
  plain.insert(plain.end(), engine.begin(), engine.end());
  const auto start = Clock::now();
  ASSERT_EQ(run(plain, -1), 0);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const auto expected = outputs(dir / "plain");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> moment(0.05, 0.95);
  for (int trial = 0; trial < trials; ++trial) {
    const std::string out = (dir / fmt::format("killed_{}", trial)).string();
    std::vector<std::string> fresh{"sim", scene, "-o", out}, resume{"sim", scene, "--resume", out};
    fresh.insert(fresh.end(), engine.begin(), engine.end());
    resume.insert(resume.end(), engine.begin(), engine.end());
    const double first = moment(rng) * seconds, second = moment(rng) * seconds;
    int code = run(fresh, first);
    for (int attempt = 0; code != 0 && attempt < 10; ++attempt) {
      // Killed before its first checkpoint (or before it made its folder, while the GPU context
      // started): nothing to resume from (exit 1), so it starts again.
      const bool any = fs::is_directory(out) &&
                       std::any_of(fs::directory_iterator(out), fs::directory_iterator(),
                                   [](const fs::directory_entry& e) { return e.path().extension() == ".tsck"; });
      code = run(any ? resume : fresh, attempt == 0 ? second : -1);
    }
    ASSERT_EQ(code, 0) << "trial " << trial;
    // What a kill during a write leaves (a hidden temporary file) is gone once a run went on.
    EXPECT_FALSE(std::any_of(
        fs::directory_iterator(out), fs::directory_iterator(),
        [](const fs::directory_entry& e) { return e.path().filename().string().starts_with("."); }))
        << "trial " << trial;
    EXPECT_EQ(outputs(out), expected) << "trial " << trial << ", killed after " << first << " s and "
                                      << second << " s of a " << seconds << " s run";
  }
}

TEST(SimResume, CpuRunKilledAtRandomMomentsEndsInTheUninterruptedState) {
  expect_killed_runs_end_the_same({"--cpu"}, 6, 20);
}

TEST(SimResume, GpuRunKilledAtRandomMomentsEndsInTheUninterruptedState) {
  expect_killed_runs_end_the_same({"--backend", "gpu"}, 2, 21);
}

TEST(SimResume, ResumeRefusesAMissingFolderAndTakesNoOutputOption) {
  const fs::path dir = test::temp_dir();
  write_file_atomically(dir / "scene.toml", scene_text());
  std::string output;
  EXPECT_EQ(test::run_tetrasand(fmt::format("sim '{}' --cpu --resume '{}'", (dir / "scene.toml").string(),
                                            (dir / "none").string()),
                                &output),
            1);
  EXPECT_NE(output.find((dir / "none").string() + ": no such folder to resume from"), std::string::npos)
      << output;
  EXPECT_EQ(test::run_tetrasand(fmt::format("sim '{}' --resume '{}' -o '{}'", (dir / "scene.toml").string(),
                                            dir.string(), dir.string()),
                                &output),
            2);
}

}  // namespace
}  // namespace ts
