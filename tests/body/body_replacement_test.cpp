// A body is replaced only as a whole, also when its writer is killed (SIGKILL) at any moment: a
// reader afterwards finds the old pair or the new pair, byte for byte, and nothing left behind.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <random>
#include <thread>

#include "body/body_file.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mass_properties.h"
#include "core/temporary_name.h"
#include "tests/body/test_bodies.h"
#include "tests/input_error.h"
#include "tests/test_meshes.h"
#include "tests/test_support.h"

namespace ts::body {
namespace {

namespace fs = std::filesystem;

// A valid 2 x 1 x 0.5 m box body of `count` particles at random places with random unit normals
// (the writer checks mass properties and normals, not where the particles are).
ParticleBody random_body(std::size_t count, std::uint64_t seed) {
  ParticleBody body;
  const TriangleMesh box = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 1.0, 0.5));
  set_mass_properties(body, compute_mass_properties(box, 1500.0));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t i = 0; i < count; ++i) {
    body.positions.emplace_back(u(rng) + 1.0f, 0.5f * u(rng) + 0.5f, 0.25f * u(rng) + 0.25f);
    body.normals.push_back(Eigen::Vector3f(u(rng), u(rng), u(rng) + 2.0f).normalized());
  }
  test::set_sampling_keys(body, 0.01);
  return body;
}

// A body's files (the name says pair: the .vtp, ParaView's copy of the particles, goes with them).
struct Pair {
  std::string json, ply, vtp;
  bool operator==(const Pair&) const = default;
};

Pair read_pair(const fs::path& dir) {
  return {read_file(dir / "b.body.json"), read_file(dir / "b.particles.ply"), read_file(dir / "b.particles.vtp")};
}

constexpr std::size_t kBodyFiles = 3;  // json, ply, vtp

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// Runs write_body(dir, "b", body) in a child process, SIGKILLed after `delay` unless it has
// already ended. Returns whether it had ended before the kill was due.
bool write_and_kill(const fs::path& dir, const ParticleBody& body, std::chrono::microseconds delay) {
  const pid_t child = ::fork();
  EXPECT_GE(child, 0);
  if (child == 0) {
    try {
      write_body(dir, "b", body);
    } catch (...) {
      ::_exit(1);
    }
    ::_exit(0);
  }
  std::this_thread::sleep_for(delay);
  int status = 0;
  const bool ended_first = ::waitpid(child, &status, WNOHANG) == child;
  if (!ended_first) {
    ::kill(child, SIGKILL);
    ::waitpid(child, &status, 0);
  }
  EXPECT_TRUE(WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) == 0));
  return ended_first;
}

std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// Microseconds after the fork: the first hidden (temporary) file seen in `dir`, the child's exit.
struct Window {
  long first_file = 0;
  long end = 0;
};

Window time_write(const fs::path& dir, const ParticleBody& body) {
  const auto start = std::chrono::steady_clock::now();
  const auto since = [&] {
    return static_cast<long>(
        std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - start)
            .count());
  };
  const pid_t child = ::fork();
  if (child == 0) {
    write_body(dir, "b", body);
    ::_exit(0);
  }
  Window window{-1, 0};
  int status = 0;
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (window.first_file < 0) {
      for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().filename().string().starts_with(".")) window.first_file = since();
      }
    }
  }
  window.end = since();
  if (window.first_file < 0) window.first_file = 0;
  return window;
}

TEST(BodyReplacement, AWriterKilledAtRandomLeavesTheOldPairOrTheNewOneByteForByte) {
  const ParticleBody old_body = random_body(5000, 1);
  const ParticleBody new_body = random_body(40000, 2);
  const fs::path reference = test::temp_dir();
  write_body(reference / "old", "b", old_body);
  write_body(reference / "new", "b", new_body);
  const Pair old_pair = read_pair(reference / "old"), new_pair = read_pair(reference / "new");
  // When, in a child as in the trials, the first temporary file appears and when the write ends:
  // the kills are spread over that window and a little around it.
  const fs::path dir = test::temp_dir();
  const Window window = time_write(dir, new_body);
  ASSERT_EQ(read_pair(dir), new_pair);
  // At least kTrials kills; more, up to kMaxTrials, while none has yet landed inside a write (under
  // a sanitizer the fork's start-up varies by more than a write lasts, so 200 can all miss).
  constexpr int kTrials = 200, kMaxTrials = 1000;
  std::mt19937_64 rng(20);
  // The window measured once is only a first guess: a loaded CI machine writes faster or slower in
  // the trials than in the timing run (all 200 kills once came after the write had ended). So the
  // window follows what the trials see: a write that ended before its kill moves the late edge in,
  // a kill that found nothing written yet moves the early edge out.
  const long margin = (window.end - window.first_file) / 10;
  long early = std::max(0L, window.first_file - margin), late = window.end + margin;
  // The window never closes below the length of a write as timed, or 0.5 ms: a window narrower than
  // the write can sit wholly before or after it once jitter has moved both edges.
  const long narrowest = std::max(500L, window.end - window.first_file);
  int trial = 0, old_found = 0, new_found = 0, interrupted = 0, ended_first = 0;
  for (; trial < kTrials || (interrupted == 0 && trial < kMaxTrials); ++trial) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    write_bytes(dir / "b.body.json", old_pair.json);
    write_bytes(dir / "b.particles.ply", old_pair.ply);
    write_bytes(dir / "b.particles.vtp", old_pair.vtp);
    const long delay = std::uniform_int_distribution<long>(early, std::max(early, late))(rng);
    const bool ended = write_and_kill(dir, new_body, std::chrono::microseconds(delay));
    const bool left_files = entries(dir) != kBodyFiles;  // temporary files or a journal were left behind
    const ParticleBody read = read_body(dir / "b.body.json");  // completes or removes what was left
    const Pair found = read_pair(dir);
    if (found == old_pair) ++old_found;
    if (found == new_pair) ++new_found;
    ASSERT_TRUE(found == old_pair || found == new_pair) << "trial " << trial << ": a mixed pair";
    EXPECT_EQ(read.positions.size(), found == old_pair ? 5000u : 40000u);
    ASSERT_EQ(entries(dir), kBodyFiles) << "trial " << trial << ": leftovers after the next read";
    if (left_files) ++interrupted;
    if (ended) {
      ++ended_first;
      late = delay;
      early = std::max(0L, std::min(early, late - narrowest));
    } else if (!left_files && found == old_pair) {
      early = delay;
      late = std::max(late, early + narrowest);
    }
  }
  std::printf(
      "%d trials (timed: first file at %.1f ms, write done at %.1f ms; kills ended in %.1f-%.1f ms): "
      "old pair %d, new pair %d, %d interrupted mid-write, %d writes ended before their kill\n",
      trial, static_cast<double>(window.first_file) / 1000.0, static_cast<double>(window.end) / 1000.0,
      static_cast<double>(early) / 1000.0, static_cast<double>(late) / 1000.0, old_found, new_found,
      interrupted, ended_first);
  EXPECT_EQ(old_found + new_found, trial);  // every trial ended in one pair or the other
  EXPECT_GT(interrupted, 0);  // the kills did land inside writes
}

TEST(BodyReplacement, ADeadWritersPublishedJournalIsCompletedByTheNextWrite) {
  const fs::path dir = test::temp_dir();
  write_body(dir, "b", random_body(100, 1));
  // A dead writer that had published its journal: new files under temporary names, renames not done.
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const std::string tmp_ply = format_temporary_name({"b.particles.ply", dead, 0, 7});
  const std::string tmp_json = format_temporary_name({"b.body.json", dead, 0, 8});
  const std::string tmp_vtp = format_temporary_name({"b.particles.vtp", dead, 0, 9});
  const fs::path other = test::temp_dir();
  write_body(other, "b", random_body(300, 2));
  fs::copy_file(other / "b.particles.ply", dir / tmp_ply);
  fs::copy_file(other / "b.body.json", dir / tmp_json);
  fs::copy_file(other / "b.particles.vtp", dir / tmp_vtp);
  write_bytes(dir / ".b.body.json.journal",
              fmt::format("tetrasand journal 1\npid {}\n{}\tb.particles.ply\n{}\tb.particles.vtp\n{}\tb.body.json\n",
                          dead, tmp_ply, tmp_vtp, tmp_json));
  EXPECT_EQ(read_body(dir / "b.body.json").positions.size(), 300u);
  EXPECT_EQ(entries(dir), kBodyFiles);
  EXPECT_EQ(read_pair(dir), read_pair(other));
}

TEST(BodyReplacement, StaleTemporaryFilesOfADeadProcessAreRemovedByTheNextRun) {
  const fs::path dir = test::temp_dir();
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  write_bytes(dir / format_temporary_name({"b.particles.ply", dead, 0, 1}), "half a file");
  write_bytes(dir / format_temporary_name({"b.body.json", dead, 0, 2}), "{");
  // The journal's own temporary file (write_atomically's name for ".b.body.json.journal").
  write_bytes(dir / format_temporary_name({".b.body.json.journal", dead, 0, 3}), "tetrasand jou");
  // Another live process's temporary file (this one's parent: alive) stays.
  const std::string live =
      format_temporary_name({"b.body.json", ::getppid(), process_start_time(::getppid()), 4});
  write_bytes(dir / live, "{");
  write_body(dir, "b", random_body(100, 1));
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{live, "b.body.json", "b.particles.ply", "b.particles.vtp"}));
}

TEST(BodyReplacement, AJournalOfALiveWriterIsRefusedNamingIt) {
  const fs::path dir = test::temp_dir();
  write_body(dir, "b", random_body(100, 1));
  write_bytes(dir / ".b.body.json.journal", fmt::format("tetrasand journal 1\npid {}\n", ::getppid()));
  const std::string error = test::input_error([&] { read_body(dir / "b.body.json"); });
  EXPECT_NE(error.find(".b.body.json.journal: process " + std::to_string(::getppid()) +
                       " is replacing these files right now"),
            std::string::npos)
      << error;
}

}  // namespace
}  // namespace ts::body
