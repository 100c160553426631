// `tetrasand sample` from the outside: refusal of open meshes with the info report, --json, outputs
// written whole (no temporary files left), and batch conversion (list files, summary CSV, --shard,
// failures that do not stop the batch). Small counts and probe sets: the quality figures themselves
// are checked in tests/sampler/sample_mesh_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
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
  EXPECT_EQ(files_in(dir), (std::set<std::string>{"sphere.body.json", "sphere.particles.ply"}));
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
  EXPECT_NE(rows[2].back().find("no-such-mesh.obj"), std::string::npos);
  EXPECT_EQ(rows[3][1], "ok");  // after the failure
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "cube.body.json"));
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
