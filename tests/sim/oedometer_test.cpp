// A small, short version of the oedometer of scripts/bench.sh oedometer (issue 18,
// bench/validation/oedometer_criteria.md): grains in a cylinder loaded and unloaded by the servo
// piston must trace a loop, the unloading branch below the loading one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "tests/scene/servo_csv.h"
#include "tests/test_support.h"

namespace ts::sim {
using namespace ts::scene;  // these tests run whole scenes through the engine
namespace {

// The bundled oedometer with 300 grains and a schedule about six times faster: seated at 250 Pa from 0.6 s,
// loaded to 3 kPa by 0.9 s, unloaded to 250 Pa by 1.2 s.
Scene small_oedometer() {
  Scene scene = load_scene(test::asset("scenes/validation/oedometer.toml"));
  scene.emitters.at(0).count = 300;
  Prop& piston = scene.props.at(0);
  piston.position.z() = 0.09;  // m: above the shorter column
  piston.servo->schedule = {{0.0, 2500.0}, {0.23, 2500.0}, {0.25, 250.0},
                            {0.6, 250.0},  {0.9, 3000.0},  {1.2, 250.0}};
  piston.servo->gain =
      2e-4;  // (m/s)/Pa: the thin bed's loop is stable at this gain, and it comes down faster
  piston.servo->every = 2;
  scene.simulation.duration = 1.2;
  return scene;
}

struct Branch {
  std::vector<double> stress, strain;  // Pa, and strain from the seated height
};

// The strain at `stress` (Pa) on a branch: where its stress first crosses it, walking from the start.
double strain_at(const Branch& b, double stress, bool rising) {
  for (std::size_t i = 1; i < b.stress.size(); ++i) {
    const bool crossed = rising ? b.stress[i] >= stress : b.stress[i] <= stress;
    if (crossed) return b.strain[i];
  }
  ADD_FAILURE() << "the branch never reaches " << stress << " Pa";
  return 0;
}

TEST(Oedometer, UnloadingBranchLiesBelowTheLoadingBranch) {
  const auto dir = test::temp_dir();
  run_scene(small_oedometer(), dir);
  const std::vector<ServoSample> rows = test::servo_samples(dir);
  const auto seat =
      std::find_if(rows.begin(), rows.end(), [](const ServoSample& s) { return s.time >= 0.6; });
  ASSERT_NE(seat, rows.end());
  const double face = 0.002;                     // m: the piston's spheres below its centre
  const double height = -seat->position - face;  // m: the bed at seating (floor at z = 0)
  EXPECT_NEAR(seat->measured, 250.0, 50.0);      // seated, not pre-loaded
  Branch loading, unloading;
  for (auto it = seat; it != rows.end(); ++it) {
    Branch& b = it->time <= 0.9 ? loading : unloading;
    b.stress.push_back(it->measured);
    b.strain.push_back((it->position - seat->position) / height);
  }
  const double half = 1500.0;  // Pa, half the peak
  const double on_loading = strain_at(loading, half, true), on_unloading = strain_at(unloading, half, false);
  RecordProperty("strain_loading", std::to_string(on_loading));
  RecordProperty("strain_unloading", std::to_string(on_unloading));
  EXPECT_GT(on_loading, 0.0);
  EXPECT_GT(on_unloading, on_loading);  // at the same stress, more strain coming back: a loop
}

}  // namespace
}  // namespace ts::sim
