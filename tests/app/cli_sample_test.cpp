// `tetrasand sample` from the outside: refusal of open meshes with the info report, --json, outputs
// written whole (no temporary files left), the verdict (last line, --json, summary.csv, --strict), and
// batch conversion (list files, summary CSV, --shard, failures that do not stop the batch). Small counts and
// probe sets: the quality figures themselves are checked in tests/sampler/sample_mesh_test.cpp.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <pty.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace ts {
namespace {

const std::string kFast = " --count 150 --probes 20000 --rounds 2 ";

std::string quoted(const std::filesystem::path& p) {
  std::string text = p.string();
  text.insert(text.begin(), '\'');
  text.push_back('\'');
  return text;
}

std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::string cell;
    bool quote = false;
    for (const char c : line) {
      if (c == '"') quote = !quote;
      else if (c == ',' && !quote) cells.push_back(cell), cell.clear();
      else cell += c;
    }
    cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::set<std::string> files_in(const std::filesystem::path& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// Runs `tetrasand ARGS` with stdout and stderr on a pseudo-terminal; returns the exit code and
// what the terminal showed.
int run_on_a_terminal(const std::vector<std::string>& args, std::string* shown) {
  int master = -1;
  const pid_t pid = ::forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) throw std::runtime_error("forkpty failed");
  if (pid == 0) {
    std::vector<char*> argv{const_cast<char*>(TETRASAND_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(TETRASAND_BINARY, argv.data());
    ::_exit(127);
  }
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(master, buffer, sizeof buffer);
    if (n > 0) shown->append(buffer, static_cast<std::size_t>(n));
    else if (n < 0 && errno == EINTR) continue;
    else break;  // EIO once the child has closed the terminal
  }
  ::close(master);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Runs a shell command whose files may grow to `max_bytes` at most; writing past that fails with
// EFBIG (SIGXFSZ is ignored), as on a full disk.
int run_with_file_size_limit(const std::string& command, rlim_t max_bytes, const std::filesystem::path& log,
                             std::string* output) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{max_bytes, max_bytes};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chains of + with literals.
    std::string line = command;
    line.append(" >'");
    line.append(log.string());
    line.append("' 2>&1");
    ::execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  *output = read_text(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST(CliSample, ProgressBarShowsOnATerminalAndNotInAPipe) {
  const auto dir = test::temp_dir();
  const std::vector<std::string> args = {"sample", test::asset("sphere.obj").string(), "-o", dir.string(), "--count",
                                         "150", "--probes", "20000", "--rounds", "2"};
  std::string shown;
  ASSERT_EQ(run_on_a_terminal(args, &shown), 0) << shown;
  // A line redrawn in place (carriage returns) with the iteration, particle count and residual.
  const std::size_t bar = shown.find("\rround 0  iteration ");
  ASSERT_NE(bar, std::string::npos) << shown;
  const std::string line = shown.substr(bar + 1, shown.find('\r', bar + 1) - bar - 1);
  EXPECT_NE(line.find("  particles "), std::string::npos) << line;
  EXPECT_NE(line.find("  residual "), std::string::npos) << line;
  EXPECT_NE(shown.find("evenness"), std::string::npos) << shown;  // and the summary after it

  std::string piped;
  std::string command = "sample";
  for (std::size_t i = 1; i < args.size(); ++i) {
    command.push_back(' ');
    command.append(quoted(std::filesystem::path(args[i])));
  }
  ASSERT_EQ(test::run_tetrasand(command, &piped), 0) << piped;
  EXPECT_EQ(piped.find('\r'), std::string::npos) << piped;
  EXPECT_EQ(piped.find("residual"), std::string::npos) << piped;
  EXPECT_NE(piped.find("evenness"), std::string::npos) << piped;
}

// "An existing output is replaced only as a whole": runs that fail (bad options; the disk filling
// up while the JSON is written) leave the previous PLY and JSON byte for byte and no temporary file;
// a successful rerun replaces both.
TEST(CliSample, AFailedRunLeavesThePreviousBodyWholeAndARerunReplacesIt) {
  const auto dir = test::temp_dir();
  // A long mesh path makes the JSON (which records it) larger than the PLY, so a file size limit
  // between the two lets the PLY through and stops the JSON.
  std::filesystem::path deep = dir;
  for (int i = 0; i < 15; ++i) deep /= std::string(240, static_cast<char>('a' + i));
  std::filesystem::create_directories(deep);
  const auto mesh = deep / "sphere.obj";
  std::filesystem::copy_file(test::asset("sphere.obj"), mesh);
  const auto out = dir / "out";
  const std::string base = "sample " + quoted(mesh) + " -o " + quoted(out) + kFast;
  std::string log;
  ASSERT_EQ(test::run_tetrasand(base, &log), 0) << log;
  const std::string ply = read_text(out / "sphere.particles.ply"), json = read_text(out / "sphere.body.json");
  ASSERT_GT(json.size(), ply.size() + 1000) << "the JSON must be the larger file";
  const std::set<std::string> pair = {"sphere.body.json", "sphere.particles.ply", "sphere.particles.vtp"};  // and the PLY as VTK points

  EXPECT_NE(test::run_tetrasand(base + "--radius 1", &log), 0) << log;  // refused: radius too large
  EXPECT_EQ(read_text(out / "sphere.particles.ply"), ply);
  EXPECT_EQ(read_text(out / "sphere.body.json"), json);

  const rlim_t limit = (ply.size() + json.size()) / 2;
  const std::string command = "MESA_SHADER_CACHE_DISABLE=true '" + std::string(TETRASAND_BINARY) + "' " + base + "--seed 5";
  EXPECT_NE(run_with_file_size_limit(command, limit, dir / "limited.log", &log), 0) << log;
  EXPECT_NE(log.find("cannot write"), std::string::npos) << log;
  EXPECT_EQ(read_text(out / "sphere.particles.ply"), ply) << "the PLY was replaced without its JSON";
  EXPECT_EQ(read_text(out / "sphere.body.json"), json);
  EXPECT_EQ(files_in(out), pair) << "temporary files left behind";

  ASSERT_EQ(test::run_tetrasand(base + "--seed 5", &log), 0) << log;
  EXPECT_NE(read_text(out / "sphere.particles.ply"), ply);
  EXPECT_NE(read_text(out / "sphere.body.json"), json);
  EXPECT_EQ(files_in(out), pair);
}

TEST(CliSample, OpenMeshIsRefusedWithTheInfoReport) {
  const auto dir = test::temp_dir();
  std::string out;
  const std::string mesh = quoted(test::assimp_model("STL/sphereWithHole.stl"));
  EXPECT_EQ(test::run_tetrasand("sample " + mesh + " -o " + quoted(dir) + kFast, &out), 1) << out;
  EXPECT_NE(out.find("is not a closed"), std::string::npos) << out;
  EXPECT_NE(out.find("boundary"), std::string::npos) << out;  // the report's hole count
  EXPECT_TRUE(files_in(dir).empty());
}

TEST(CliSample, SignWindingSamplesAnOpenMeshWithAWarning) {
  const std::string mesh = quoted(test::assimp_model("STL/sphereWithHole.stl"));
  for (const std::string flag : {"--sign winding", "--allow-open"}) {  // --allow-open: the older name
    const auto dir = test::temp_dir();
    std::string out;
    ASSERT_EQ(test::run_tetrasand("sample " + mesh + " -o " + quoted(dir) + kFast + flag + " --json", &out), 0) << out;
    EXPECT_NE(out.find("not a closed solid"), std::string::npos) << out;
    EXPECT_NE(out.find("winding-number solid"), std::string::npos) << out;
    const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
    EXPECT_EQ(json.at("mass_properties_method").get<std::string>(), "winding_cells") << flag;
    EXPECT_GT(json.at("mass_properties_cell").get<double>(), 0.0);
    EXPECT_GT(json.at("volume").get<double>(), 0.0);
  }
}

TEST(CliSample, JsonPrintsTheBodyAndOnlyFinishedFilesRemain) {
  const auto dir = test::temp_dir();
  std::string out;
  ASSERT_EQ(test::run_tetrasand("-q sample " + quoted(test::asset("sphere.obj")) + " -o " + quoted(dir) + kFast + "--json", &out),
            0)
      << out;
  const auto json = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(json.at("particles").get<std::string>(), "sphere.particles.ply");
  EXPECT_GE(json.at("particle_count").get<int>(), 140);
  EXPECT_TRUE(json.at("quality").contains("covering_over_r"));
  EXPECT_EQ(json.at("format_version").get<int>(), 3);
  // The certificate's figures, beside the probes' (which can never exceed the certified bound).
  const auto& q = json.at("quality");
  EXPECT_TRUE(q.at("coverage_certified").is_boolean());
  EXPECT_GE(q.at("covering_bound_over_r").get<double>(), q.at("covering_over_r").get<double>());
  EXPECT_LE(q.at("covering_lower_over_r").get<double>(), q.at("covering_bound_over_r").get<double>());
  EXPECT_EQ(q.at("uncovered_subtriangles").get<int>() == 0, q.at("coverage_certified").get<bool>());
  EXPECT_GT(q.at("certificate_floor").get<double>(), 0.0);
  // The verdict and the thin features, which only the run knows (not in the body.json file).
  EXPECT_EQ(json.at("verdict").get<std::string>(), "body OK") << out;
  EXPECT_FALSE(json.at("verdict_reasons").empty());
  EXPECT_EQ(json.at("thin_features").at("triangles").get<int>(), 0);
  EXPECT_FALSE(nlohmann::json::parse(read_text(dir / "sphere.body.json")).contains("verdict"));
  EXPECT_EQ(files_in(dir), (std::set<std::string>{"sphere.body.json", "sphere.particles.ply", "sphere.particles.vtp"}));
}

std::string last_line(const std::string& text) {
  const std::size_t end = text.find_last_not_of('\n');
  if (end == std::string::npos) return "";
  const std::size_t start = text.rfind('\n', end);
  return text.substr(start == std::string::npos ? 0 : start + 1,
                     end - (start == std::string::npos ? 0 : start + 1) + 1);
}

// `tetrasand ARGS` with the fast sampling options; checks its exit code, returns what it printed.
std::string sample_fast(const std::string& args, int expected_code) {
  std::string out;
  EXPECT_EQ(test::run_tetrasand(args + kFast, &out), expected_code) << out;
  return out;
}

// The issue's case: a body with holes (an open mesh, sampled by winding number: grains can get in
// through its holes) is short of OK, and --strict makes that exit 1, after writing the body.
TEST(CliSample, StrictExitsOneOnABodyWithHolesAndZeroOnAnOkBody) {
  const std::string sphere = sample_fast(
      "sample " + quoted(test::asset("sphere.obj")) + " -o " + quoted(test::temp_dir()) + " --strict", 0);
  EXPECT_EQ(last_line(sphere).rfind("verdict: body OK: coverage certified", 0), 0u) << sphere;

  const std::string open =
      "sample " + quoted(test::assimp_model("STL/sphereWithHole.stl")) + " --sign winding -o ";
  const std::string lenient = sample_fast(open + quoted(test::temp_dir()), 0);
  EXPECT_EQ(last_line(lenient).rfind("verdict: usable with caveats: ", 0), 0u) << lenient;
  EXPECT_NE(last_line(lenient).find("holes are not covered"), std::string::npos) << lenient;
  const auto dir = test::temp_dir();
  const std::string strict = sample_fast(open + quoted(dir) + " --strict --json", 1);
  const auto json = nlohmann::json::parse(strict.substr(strict.find("{\n")));
  EXPECT_EQ(json.at("verdict").get<std::string>(), "usable with caveats");
  EXPECT_EQ(files_in(dir),
            (std::set<std::string>{"sphereWithHole.body.json", "sphereWithHole.particles.ply", "sphereWithHole.particles.vtp"}));
}

// The bundled 2 mm plate at 150 particles (r about 7 mm): all of it is thinner than the spacing, one
// region, named in --json with its box and the radius that resolves it; at that radius (about 2,100
// particles) nothing is thin any more.
TEST(CliSample, JsonNamesTheThinRegionsAndTheRadiusThatResolvesThem) {
  const auto dir = test::temp_dir();
  const std::string out =
      sample_fast("-q sample " + quoted(test::asset("plate.obj")) + " -o " + quoted(dir) + " --json", 0);
  const auto json = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(json.at("verdict").get<std::string>(), "usable with caveats");
  const auto& thin = json.at("thin_features");
  EXPECT_GT(thin.at("area_share").get<double>(), 0.9) << thin;
  ASSERT_GE(thin.at("region_count").get<int>(), 1) << thin;
  const auto& largest = thin.at("regions").at(0);
  EXPECT_LT(largest.at("thinnest").get<double>(), 0.0021) << thin;
  const double radius = json.at("particle_radius").get<double>();
  EXPECT_LT(largest.at("resolving_radius").get<double>(), radius) << thin;
  EXPECT_EQ(largest.at("box_min").size(), 3u);
  bool named = false;
  for (const auto& reason : json.at("verdict_reasons"))
    named = named || reason.get<std::string>().find("thin features") != std::string::npos;
  EXPECT_TRUE(named) << json.at("verdict_reasons");

  const std::string resolving = fmt::format("{:.3g}", largest.at("resolving_radius").get<double>());
  std::string again;
  ASSERT_EQ(test::run_tetrasand("-q sample " + quoted(test::asset("plate.obj")) + " -o " + quoted(dir) +
                                    " --probes 20000 --json --radius " + resolving,
                                &again),
            0)
      << again;
  const auto resolved = nlohmann::json::parse(again.substr(again.find('{')));
  EXPECT_EQ(resolved.at("thin_features").at("triangles").get<int>(), 0) << resolved.at("thin_features");
}

// The text report on the thin plate names its region and says why no smaller radius on the region alone is
// offered (docs/body-format.md, "Thin features": a body has one particle radius).
TEST(CliSample, ThinFeatureReportSaysWhyNoLocalRadiusIsOffered) {
  const std::string out =
      sample_fast("sample " + quoted(test::asset("plate.obj")) + " -o " + quoted(test::temp_dir()), 0);
  EXPECT_NE(out.find("thin features"), std::string::npos) << out;
  EXPECT_NE(out.find("a smaller radius on these regions alone is not offered (a body has one particle radius"),
            std::string::npos)
      << out;
}

// --timings: the kernels' times and the round trips, none in the iterations between the checks (the
// GPU relaxation: auto relaxes on the CPU on a software renderer).
TEST(CliSample, TimingsReportNoRoundTripBetweenConvergenceChecks) {
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sample " + quoted(test::asset("sphere.obj")) + " -o " +
                                    quoted(test::temp_dir()) + kFast + "--backend gpu --timings",
                                &out),
            0)
      << out;
  EXPECT_NE(out.find("sampler/relax.comp"), std::string::npos) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(relaxation iterations between checks \(\d+\) +0 )")))
      << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(convergence checks \((\d+)\) +\d+ .* 1 per check)")))
      << out;
  EXPECT_NE(out.find("sample in all"), std::string::npos) << out;
}

TEST(CliSample, ReportPrintsTheCertificateAndTheHolesItLeaves) {
  const std::string sphere = quoted(test::asset("sphere.obj"));
  {  // the default rounds close the holes: certified
    std::string out;
    ASSERT_EQ(
        test::run_tetrasand(
            "sample " + sphere + " -o " + quoted(test::temp_dir()) + " --count 150 --probes 20000", &out),
        0)
        << out;
    EXPECT_NE(out.find("certificate      certified: every surface point lies within r"), std::string::npos)
        << out;
    EXPECT_NE(out.find("probes           covering radius"), std::string::npos) << out;
  }
  {  // one relaxation step and no rounds leave the random seeds' holes: reported, with where they are
    std::string out;
    ASSERT_EQ(test::run_tetrasand("sample " + sphere + " -o " + quoted(test::temp_dir()) +
                                      " --count 150 --probes 20000 --rounds 0 --max-iterations 1",
                                  &out),
              0)
        << out;
    EXPECT_NE(out.find("certificate      NOT certified: covering radius <="), std::string::npos) << out;
    EXPECT_NE(out.find(" r deep at ("), std::string::npos) << out;
    EXPECT_NE(out.find("coverage target not certified after 0 rounds"), std::string::npos) << out;
  }
}

// The report names the device and the SDF path, with the scan conversion's, the relaxation's and the
// certificate's seconds; --json carries the same figures under "run", and --timings a stage table.
TEST(CliSample, ReportNamesTheDeviceAndTheStageTimes) {
  const std::string sphere = quoted(test::asset("sphere.obj"));
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sample " + sphere + " -o " + quoted(test::temp_dir()) + kFast +
                                    "--sdf-backend gpu --timings",
                                &out),
            0)
      << out;
  EXPECT_TRUE(std::regex_search(
      out,
      std::regex(
          R"(  device           .*\(device \d+, (software|hardware)\): SDF by GPU scan (compute|geometry) )"
          R"(\(calibrated [^)]*\) [0-9.]+ s, )"
          R"(relaxation [0-9.]+ s, certificate [0-9.]+ s)")))
      << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(relaxation \(all rounds\) +[0-9.]+ +[0-9.]+%)"))) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(probe pass \(20000 probes\))"))) << out;
  ASSERT_EQ(test::run_tetrasand("-q sample " + sphere + " -o " + quoted(test::temp_dir()) + kFast +
                                    "--sdf-backend cpu --json",
                                &out),
            0)
      << out;
  const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
  const auto& run = json.at("run");
  EXPECT_EQ(run.at("sdf_backend"), "cpu");
  EXPECT_EQ(run.at("probes"), 20000);
  EXPECT_FALSE(run.at("device").get<std::string>().empty());
  const auto& t = run.at("seconds");
  double stages = 0.0;
  for (const char* key : {"context", "load", "plan", "sdf", "setup", "relaxation", "projection",
                          "certificate", "injection", "probes", "thin_features", "body", "write"}) {
    EXPECT_GE(t.at(key).get<double>(), 0.0) << key;
    stages += t.at(key).get<double>();
  }
  EXPECT_GT(t.at("sdf").get<double>(), 0.0);
  EXPECT_GT(t.at("relaxation").get<double>(), 0.0);
  EXPECT_LE(stages, t.at("total").get<double>() * 1.001 + 1e-3);  // the stages do not overlap
  EXPECT_GE(stages, 0.5 * t.at("total").get<double>());           // and are most of the run
  ASSERT_EQ(test::run_tetrasand("sample " + sphere + " -o " + quoted(test::temp_dir()) + kFast +
                                    "--sdf-backend openvdb --backend cpu --timings",
                                &out),
            0)
      << out;
  EXPECT_NE(out.find("SDF by OpenVDB's meshToVolume on the CPU"), std::string::npos) << out;
  EXPECT_NE(out.find("SDF: OpenVDB meshToVolume (CPU), NanoVDB"), std::string::npos) << out;
  EXPECT_NE(test::run_tetrasand(
                "sample " + sphere + " -o " + quoted(test::temp_dir()) + kFast + "--sdf-backend cuda", &out),
            0);
}

// --preview is part of the run's time: a key of run.seconds counted in the total, a row of the
// --timings stage table and a line of the report with its seconds.
TEST(CliSample, PreviewTimeIsInTheJsonTheStageTableAndTheReport) {
  const std::string sphere = quoted(test::asset("sphere.obj"));
  const auto dir = test::temp_dir();
  std::string out;
  ASSERT_EQ(test::run_tetrasand("-q sample " + sphere + " -o " + quoted(dir) + kFast + "--preview --json", &out), 0)
      << out;
  const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
  const auto& t = json.at("run").at("seconds");
  ASSERT_TRUE(t.contains("preview")) << t.dump();
  EXPECT_GT(t.at("preview").get<double>(), 0.0);
  EXPECT_LE(t.at("preview").get<double>() + t.at("write").get<double>(), t.at("total").get<double>());
  EXPECT_TRUE(std::filesystem::exists(dir / "sphere.preview.png"));
  ASSERT_EQ(test::run_tetrasand("-q sample " + sphere + " -o " + quoted(dir) + kFast + "--json", &out), 0) << out;
  EXPECT_FALSE(nlohmann::json::parse(out.substr(out.find("{\n"))).at("run").at("seconds").contains("preview"))
      << "no preview, no preview time";
  ASSERT_EQ(test::run_tetrasand("sample " + sphere + " -o " + quoted(dir) + kFast + "--preview --timings", &out), 0)
      << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(preview \(field, drawing, PNG\) +[0-9.]+ +[0-9.]+%)"))) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(  preview          .*sphere\.preview\.png, [0-9.]+ s on the (CPU|GPU))")))
      << out;
}

TEST(CliSample, FillCountsTheInteriorParticlesInTheJsonAndThePly) {
  const auto dir = test::temp_dir();
  std::string out;
  ASSERT_EQ(test::run_tetrasand("-q sample " + quoted(test::asset("sphere.obj")) + " -o " + quoted(dir) + kFast + "--fill --json", &out),
            0)
      << out;
  const auto json = nlohmann::json::parse(out.substr(out.find('{')));
  const int interior = json.at("interior_particle_count").get<int>();
  EXPECT_GT(interior, 10);  // 19 measured for 150 surface particles (r about 7.6 mm in a 5 cm ball)
  const std::string ply = read_text(dir / "sphere.particles.ply");
  EXPECT_NE(ply.find("element vertex " + std::to_string(json.at("particle_count").get<int>()) + "\n"), std::string::npos);
  EXPECT_GE(json.at("particle_count").get<int>(), interior + 140);
}

// The GPU path builds the field on the GPU and relaxes on it there: no byte of it is read back between
// the scan and the relaxation, and the body still meets its targets. Relaxing on the CPU takes the
// field through the host, and says so.
TEST(CliSample, GpuPathRelaxesOnTheFieldItScannedWithNothingReadBack) {
  const std::string bunny = quoted(test::asset("bunny.obj"));
  const auto dir = test::temp_dir();
  std::string out;
  ASSERT_EQ(test::run_tetrasand("-q sample " + bunny + " -o " + quoted(dir) + " --count 400 --probes 20000 "
                                "--sdf-backend gpu --backend gpu --json", &out),
            0)
      << out;
  auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
  const auto& run = json.at("run");
  EXPECT_EQ(run.at("sdf_backend"), "gpu");
  EXPECT_EQ(run.at("relax_backend"), "gpu");
  const auto& sdf = run.at("sdf");
  EXPECT_EQ(sdf.at("readback_bytes").get<std::size_t>(), 0u) << sdf.dump();
  EXPECT_TRUE(sdf.at("gpu_resident").get<bool>());
  EXPECT_EQ(sdf.at("host_bytes").get<std::size_t>(), 0u);
  EXPECT_GT(sdf.at("band_voxels").get<std::size_t>(), 10000u);
  EXPECT_GT(sdf.at("gpu_bytes").get<std::size_t>(), 4 * sdf.at("band_voxels").get<std::size_t>());
  const auto& q = json.at("quality");
  EXPECT_TRUE(q.at("coverage_certified").get<bool>()) << out;
  EXPECT_TRUE(q.at("converged").get<bool>()) << out;
  EXPECT_LT(q.at("max_abs_phi_over_r").get<double>(), 1e-3) << out;
  // The bunny's ears are thinner than 400 particles resolve (a finding of the mesh, from the exact
  // distance), so the verdict is the host path's, not "body OK".
  const std::string verdict = json.at("verdict").get<std::string>();
  EXPECT_NE(verdict, "not usable") << out;

  ASSERT_EQ(test::run_tetrasand("-q sample " + bunny + " -o " + quoted(test::temp_dir()) + " --count 400 "
                                "--probes 20000 --sdf-backend gpu --backend cpu --json", &out),
            0)
      << out;
  json = nlohmann::json::parse(out.substr(out.find("{\n")));
  const auto& host = json.at("run").at("sdf");
  EXPECT_FALSE(host.at("gpu_resident").get<bool>());
  EXPECT_EQ(host.at("readback_bytes").get<std::size_t>(), 20 * host.at("band_voxels").get<std::size_t>());
  EXPECT_EQ(json.at("verdict").get<std::string>(), verdict) << out;
}

// A field that does not fit the GPU's memory (capped here by TETRASAND_GPU_MEMORY_MIB, so llvmpipe meets
// it with a small mesh) stops before any work with exit 3, writes nothing, and names the finest voxel
// that fits, which then runs under the same cap.
TEST(CliSample, AFieldAboveTheGpuMemoryStopsWithExitThreeNamingTheResolutionThatFits) {
  const std::string sphere = quoted(test::asset("sphere.obj"));
  const auto dir = test::temp_dir();
  ::setenv("TETRASAND_GPU_MEMORY_MIB", "0.25", 1);
  std::string out;
  const int code = test::run_tetrasand("sample " + sphere + " -o " + quoted(dir) + kFast +
                                       "--voxel 0.001 --sdf-backend gpu --backend gpu", &out);
  const bool wrote_nothing = files_in(dir).empty();  // before the rerun: temp_dir() is one folder a test
  std::smatch voxel;
  const bool named = std::regex_search(out, voxel, std::regex(R"(largest resolution that fits is a voxel of [0-9.e-]+ m \(\d+ x \d+ x \d+ voxels\): --voxel ([0-9.e-]+))"));
  std::string rerun;
  const auto rerun_dir = dir / "rerun";
  std::filesystem::create_directories(rerun_dir);
  const int rerun_code = named ? test::run_tetrasand("sample " + sphere + " -o " + quoted(rerun_dir) + kFast +
                                                         "--voxel " + voxel[1].str() + " --sdf-backend gpu --backend gpu",
                                                     &rerun)
                               : -1;
  ::unsetenv("TETRASAND_GPU_MEMORY_MIB");
  EXPECT_EQ(code, 3) << out;
  EXPECT_TRUE(named) << out;
  EXPECT_NE(out.find("(TETRASAND_GPU_MEMORY_MIB)"), std::string::npos) << out;
  EXPECT_TRUE(wrote_nothing);
  EXPECT_EQ(rerun_code, 0) << rerun;
}

TEST(CliSample, SdfBudgetCapsTheSparseFieldAndNamesWhatFits) {
  const std::string sphere = quoted(test::asset("sphere.obj"));
  {  // a fine voxel on a 10 cm sphere: about 1M band voxels, ~12 MiB of NanoVDB, refused under 8 MiB
    const auto dir = test::temp_dir();
    std::string out;
    EXPECT_EQ(test::run_tetrasand("sample " + sphere + " -o " + quoted(dir) + kFast + "--voxel 0.0005 --sdf-budget-mib 8", &out),
              1)
        << out;
    EXPECT_NE(out.find("above the budget of 8 MiB"), std::string::npos) << out;
    EXPECT_NE(out.find("a --voxel of at least"), std::string::npos) << out;
    EXPECT_TRUE(files_in(dir).empty());
  }
  {  // the automatic voxel stays r / 2 and is never coarsened to fit: the run stops with the count that fits
    const auto dir = test::temp_dir();
    std::string out;
    EXPECT_EQ(test::run_tetrasand("sample " + sphere + " -o " + quoted(dir) + " --count 600 --probes 20000 --sdf-budget-mib 1", &out),
              1)
        << out;
    EXPECT_NE(out.find("particles fit it"), std::string::npos) << out;
    EXPECT_TRUE(files_in(dir).empty());
  }
  {  // under the default budget the voxel is r / 2
    const auto dir = test::temp_dir();
    std::string out;
    ASSERT_EQ(test::run_tetrasand("sample " + sphere + " -o " + quoted(dir) + " --count 300 --probes 20000 --rounds 2 --json", &out),
              0)
        << out;
    const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
    EXPECT_NEAR(json.at("sdf_voxel_size").get<double>(), json.at("particle_radius").get<double>() / 2.0, 1e-9);
  }
}

TEST(CliSample, BatchWritesASummaryAndAFailureDoesNotStopIt) {
  const auto dir = test::temp_dir();
  const auto list = dir / "meshes.txt";
  std::ofstream(list) << "# two good meshes and a missing one\n"
                      << test::asset("sphere.obj").string() << "\n\nno-such-mesh.obj\n"
                      << test::asset("cube.obj").string() << "\n";
  std::string out;
  const int code = test::run_tetrasand("sample @" + quoted(list) + " -o " + quoted(dir / "out") + kFast, &out);
  EXPECT_EQ(code, 1) << out;  // some failed
  const auto rows = read_csv(dir / "out" / "summary.csv");
  ASSERT_EQ(rows.size(), 4u) << out;
  EXPECT_EQ(rows[0][0], "mesh");
  EXPECT_EQ(rows[1][1], "ok");
  EXPECT_EQ(rows[2][1], "failed");
  // The certificate's columns: filled for a converted mesh, empty for a failed one.
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(rows[0].begin(), rows[0].end(), name) - rows[0].begin());
  };
  for (const char* name : {"coverage_certified", "covering_bound_over_r", "uncovered_subtriangles"}) {
    const std::size_t k = column(name);
    ASSERT_LT(k, rows[0].size()) << name;
    EXPECT_FALSE(rows[1][k].empty()) << name;
    EXPECT_TRUE(rows[2][k].empty()) << name;
  }
  EXPECT_GE(std::stod(rows[1][column("covering_bound_over_r")]),
            std::stod(rows[1][column("covering_over_r")]));
  // The verdict and its reasons: for a converted mesh, not for a failed one.
  ASSERT_LT(column("verdict_reasons"), rows[0].size());
  EXPECT_EQ(rows[1][column("verdict")], "body OK") << rows[1][column("verdict_reasons")];
  EXPECT_FALSE(rows[1][column("verdict_reasons")].empty());
  EXPECT_TRUE(rows[2][column("verdict")].empty());
  EXPECT_NE(rows[2].back().find("no-such-mesh.obj"), std::string::npos);
  EXPECT_EQ(rows[3][1], "ok");  // after the failure
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "cube.body.json"));
}

// --strict in a batch: every mesh is still converted and written; a body short of OK is its row's
// exit code 1 and the batch's.
TEST(CliSample, StrictBatchConvertsEveryMeshAndExitsOneForABodyShortOfOk) {
  const auto dir = test::temp_dir();
  const auto list = dir / "meshes.txt";
  std::ofstream(list) << test::asset("sphere.obj").string() << "\n"
                      << test::asset("plate.obj").string() << "\n";
  const std::string out =
      sample_fast("sample @" + quoted(list) + " -o " + quoted(dir / "out") + " --strict", 1);
  EXPECT_NE(out.find("2 of 2 meshes converted, 1 of them short of 'body OK' (exit 1: --strict)"),
            std::string::npos)
      << out;
  const auto rows = read_csv(dir / "out" / "summary.csv");
  ASSERT_EQ(rows.size(), 3u) << out;
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(rows[0].begin(), rows[0].end(), name) - rows[0].begin());
  };
  EXPECT_EQ(rows[1][column("verdict")], "body OK");
  EXPECT_EQ(rows[1][column("exit_code")], "0");
  EXPECT_EQ(rows[2][column("verdict")], "usable with caveats");
  EXPECT_NE(rows[2][column("verdict_reasons")].find("thin features"), std::string::npos);
  EXPECT_EQ(rows[2][column("status")], "ok");
  EXPECT_EQ(rows[2][column("exit_code")], "1");
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "plate.body.json"));
}

TEST(CliSample, ShardsSplitTheListDeterministicallyAndCoverItOnce) {
  const auto dir = test::temp_dir();
  const auto list = dir / "meshes.txt";
  std::ofstream(list) << test::asset("sphere.obj").string() << "\n"
                      << test::asset("cube.obj").string() << "\n"
                      << test::asset("torus.obj").string() << "\n";
  std::multiset<std::string> converted;
  for (int shard = 0; shard < 2; ++shard) {
    std::string out;
    ASSERT_EQ(test::run_tetrasand("sample --list " + quoted(list) + " --shard " + std::to_string(shard) + "/2 -o " +
                                      quoted(dir / "out") + kFast,
                                  &out),
              0)
        << out;
    const auto rows = read_csv(dir / "out" / ("summary-" + std::to_string(shard) + "-of-2.csv"));
    for (std::size_t i = 1; i < rows.size(); ++i) converted.insert(std::filesystem::path(rows[i][0]).stem().string());
    if (shard == 0) {
      ASSERT_EQ(rows.size(), 3u);  // meshes 0 and 2
      EXPECT_NE(rows[1][0].find("sphere"), std::string::npos);
      EXPECT_NE(rows[2][0].find("torus"), std::string::npos);
    }
  }
  EXPECT_EQ(converted, (std::multiset<std::string>{"cube", "sphere", "torus"}));
}

TEST(CliSample, BadShardIsAUsageError) {
  std::string out;
  EXPECT_EQ(test::run_tetrasand("sample " + quoted(test::asset("cube.obj")) + " --shard 2/2", &out), 2) << out;
}

}  // namespace
}  // namespace ts
