// The value checker (core/checked_values.h) as the command line meets it: `sim` refuses a run that
// would take no step, stops with exit 4 when its last step carries a grain through a wall, and
// `export lammps` refuses a deck that would hold a non-finite number.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

namespace ts {
namespace {

namespace fs = std::filesystem;

// One 5 mm grain over a smooth floor, thrown down at 20 m/s, with `simulation` keys.
fs::path thrown_grain_scene(const fs::path& dir, const std::string& simulation) {
  const fs::path file = dir / "scene.toml";
  write_file_atomically(file, std::string(test::kCoarseSand) +
                                  test::smooth_plane("[0.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]") +
                                  test::box_emitter("fill", "[-0.03, -0.03, 0.01]", "[0.03, 0.03, 0.05]", 1,
                                                    "velocity = [0.0, 0.0, -20.0]\n") +
                                  "[simulation]\n" + simulation + "[output]\nply = false\n");
  return file;
}

TEST(CliValues, SimRefusesARunOfNoStepsNamingTheKey) {
  const fs::path dir = test::temp_dir();
  const fs::path scene = thrown_grain_scene(dir, "duration = 0.01\ndt = inf\n");
  std::string out;
  EXPECT_EQ(test::run_tetrasand(
                "sim " + test::quoted(scene) + " -o " + test::quoted(dir / "out") + " --backend cpu", &out),
            1)
      << out;
  EXPECT_NE(out.find("scene.toml:25: simulation.dt: dt must be finite and > 0 (got inf)"), std::string::npos)
      << out;
}

TEST(CliValues, SimStopsWithExit4WhenTheLastStepCarriesAGrainThroughTheFloor) {
  const fs::path dir = test::temp_dir();
  const fs::path scene = thrown_grain_scene(dir, "duration = 0.01\ndt = 0.01\ncheck_time_step = false\n");
  std::string out;
  EXPECT_EQ(test::run_tetrasand(
                "sim " + test::quoted(scene) + " -o " + test::quoted(dir / "out") + " --backend cpu", &out),
            4)
      << out;
  EXPECT_NE(out.find("has passed through the plane of [[boundary]] at line 12"), std::string::npos) << out;
}

TEST(CliValues, ExportRefusesAVelocityWhoseEnergyOverflows) {
  const fs::path dir = test::temp_dir();
  const fs::path scene = thrown_grain_scene(dir, "duration = 0.01\n");
  std::string text = read_file(scene);
  text.replace(text.find("-20.0"), 5, "-1.0e300");
  write_file_atomically(scene, text);
  std::string out;
  EXPECT_EQ(
      test::run_tetrasand("export lammps " + test::quoted(scene) + " -o " + test::quoted(dir / "deck"), &out),
      1)
      << out;
  EXPECT_NE(out.find("emitter.velocity: a speed of 1e+300 m/s exceeds the speed of light"), std::string::npos)
      << out;
  EXPECT_FALSE(fs::exists(dir / "deck" / "in.tetrasand"));
}

}  // namespace
}  // namespace ts
