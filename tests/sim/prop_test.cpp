// Converted props in sand (issue 6): the bundled scenes assets/scenes/prop_drop.toml (a dynamic cube
// dropped into a bed) and blade.toml (a kinematic plate pushing grains), run on the CPU reference.
// The props are `tetrasand sample` bodies committed under assets/bodies/.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <vector>

#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "tests/test_support.h"

namespace ts::sim {
using namespace ts::scene;  // these tests run whole scenes through the engine
namespace {

std::vector<std::size_t> grains_of(const World& w) {
  std::vector<std::size_t> out;
  for (std::size_t b = 0; b < w.bodies.size(); ++b)
    if (w.bodies.motion[b] == MotionType::Dynamic && w.bodies.particle_count[b] == 4) out.push_back(b);
  return out;
}

// The prop: the one body that is neither a grain nor a static boundary.
std::size_t prop_of(const World& w) {
  for (std::size_t b = 0; b < w.bodies.size(); ++b)
    if (w.bodies.motion[b] != MotionType::Static && w.bodies.particle_count[b] != 4) return b;
  ADD_FAILURE() << "no prop";
  return 0;
}

// A point in the prop's mesh frame (the body file's coordinates, centre of mass at the origin for
// the committed bodies).
Eigen::Vector3d to_prop_frame(const World& w, std::size_t prop, const Eigen::Vector3d& x) {
  return w.bodies.orientation[prop].conjugate() * (x - w.bodies.position[prop]);
}

TEST(Props, DynamicCubeDroppedOntoSandComesToRestOnItAndNoGrainPassesThrough) {
  const Scene scene = load_scene(test::asset("scenes/prop_drop.toml"));
  const double half = 0.05;  // m, the cube's half side
  std::size_t deepest_inside = 0;
  double lowest_bottom = 1e9, landing_speed = 0;
  World final_state;
  RunHooks hooks;
  hooks.on_output = [&](const World& w, const StepStats&, std::int64_t) {
    const std::size_t cube = prop_of(w);
    landing_speed = std::max(landing_speed, w.bodies.linear_velocity[cube].norm());
    // A grain sphere centre deeper inside the cube than its particle layer: a grain went through.
    const double inner = half - w.particles.radius[w.bodies.first_particle[cube]];
    for (std::size_t g : grains_of(w)) {
      for (std::uint32_t i = w.bodies.first_particle[g]; i < w.bodies.first_particle[g] + 4; ++i) {
        const Eigen::Vector3d x = w.bodies.position[g] + w.bodies.orientation[g] * w.particles.offset[i];
        deepest_inside += to_prop_frame(w, cube, x).cwiseAbs().maxCoeff() < inner ? 1 : 0;
      }
    }
    double bottom = 1e9;
    for (std::uint32_t i = w.bodies.first_particle[cube]; i < w.bodies.first_particle[cube] + w.bodies.particle_count[cube];
         ++i) {
      bottom = std::min(bottom, (w.bodies.position[cube] + w.bodies.orientation[cube] * w.particles.offset[i]).z());
    }
    lowest_bottom = std::min(lowest_bottom, bottom);
    final_state = w;
  };
  run_scene(scene, test::temp_dir(), hooks);
  const std::size_t cube = prop_of(final_state);
  EXPECT_GT(landing_speed, 2.0);  // m/s: it fell 30 cm before touching sand
  EXPECT_EQ(deepest_inside, 0u);
  // At rest (slower than a millimetre per 10 ms) ...
  EXPECT_LT(final_state.bodies.linear_velocity[cube].norm(), 0.1);
  EXPECT_LT(final_state.bodies.angular_velocity[cube].norm(), 1.0);
  // ... on the sand, not on the box floor: at least a grain's bounding radius of sand below it.
  const double grain_bound = make_tetrahedral_grain(5e-3, 1e-2, 2600).bounding_radius;
  EXPECT_GT(lowest_bottom, grain_bound);
}

TEST(Props, KinematicBladePushesGrainsAndNoneSlipsThrough) {
  const Scene scene = load_scene(test::asset("scenes/blade.toml"));
  std::vector<double> start_x, side;  // per grain: first x, last side of the blade (+1 ahead, -1 behind)
  std::size_t passed = 0;
  World first, last;
  RunHooks hooks;
  hooks.on_output = [&](const World& w, const StepStats&, std::int64_t) {
    const std::size_t blade = prop_of(w);
    const auto grains = grains_of(w);
    // Positions are taken when the blade enters the bed (the bed has settled by then).
    if (start_x.empty() && w.bodies.position[blade].x() > -0.16) {
      first = w;
      for (std::size_t g : grains) start_x.push_back(w.bodies.position[g].x());
      side.assign(grains.size(), 0.0);
    }
    if (start_x.empty()) return;
    const double top = w.bodies.position[blade].z() + 0.03;  // m, the upright plate's top edge
    for (std::size_t k = 0; k < grains.size(); ++k) {
      const Eigen::Vector3d& x = w.bodies.position[grains[k]];
      const double s = x.x() > w.bodies.position[blade].x() ? 1.0 : -1.0;
      // Crossing from ahead to behind below the top edge means passing through the plate.
      if (side[k] > 0 && s < 0 && x.z() < top) ++passed;
      side[k] = s;
    }
    last = w;
  };
  run_scene(scene, test::temp_dir(), hooks);
  EXPECT_EQ(passed, 0u);
  const std::size_t blade = prop_of(last);
  // It kept its prescribed motion (kinematic: forces do not act on it).
  EXPECT_NEAR(last.bodies.position[blade].x(), first.bodies.position[blade].x() + 0.2 * (last.time - first.time), 1e-9);
  EXPECT_EQ(last.bodies.linear_velocity[blade], Eigen::Vector3d(0.2, 0, 0));
  // Grains that started in the swept part of the bed moved on in +x, at least half the blade's
  // travel through the bed on average; grains far ahead barely moved.
  const double front = last.bodies.position[blade].x();  // m
  const auto grains = grains_of(last);
  double swept = 0, far = 0;
  int n_swept = 0, n_far = 0;
  for (std::size_t k = 0; k < grains.size(); ++k) {
    const double moved = last.bodies.position[grains[k]].x() - start_x[k];
    if (start_x[k] < front - 0.03) {
      swept += moved;
      ++n_swept;
    } else if (start_x[k] > front + 0.1) {
      far += moved;
      ++n_far;
    }
  }
  ASSERT_GT(n_swept, 20);
  ASSERT_GT(n_far, 20);
  const double travel = front - (-0.15);  // m, blade travel inside the bed
  EXPECT_GT(swept / n_swept, 0.5 * travel);
  EXPECT_LT(std::abs(far / n_far), 0.01);
}


// The run summary (issue 17): prop_drop's cube is a dynamic body but not a grain, in the result, in
// metrics.csv and in `tetrasand sim`'s report, which also names every output it wrote.
TEST(Props, RunSummaryCountsThePropApartFromTheGrainsAndListsEveryOutput) {
  Scene scene = load_scene(test::asset("scenes/prop_drop.toml"));
  scene.simulation.duration = 0.005;  // s: a few steps
  scene.output.vtp = true;
  const auto dir = test::temp_dir();
  const RunResult r = run_scene(scene, dir);
  EXPECT_EQ(r.grains, 360u);
  EXPECT_EQ(r.bodies.grains, 360u);
  EXPECT_EQ(r.bodies.dynamic_props, 1u);
  EXPECT_EQ(r.bodies.kinematic_props + r.bodies.static_props + r.bodies.rough_walls, 0u);
  EXPECT_EQ(r.bodies.smooth_planes, 5u);
  ASSERT_EQ(r.files.size(), 4u);  // metrics.csv, the ply and vtp particles and the vtp files' collection
  for (const OutputRecord& f : r.files) EXPECT_EQ(f.count, r.outputs) << f.pattern;
  EXPECT_EQ(r.files[2].pattern, "particles_NNNNNN.vtp");
  EXPECT_EQ(r.files[3].pattern, "particles.pvd");
  std::ifstream csv(dir / "metrics.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_EQ(row.substr(row.find(',', row.find(',') + 1) + 1, 4), "360,") << row;

  std::string output;
  const auto out = test::temp_dir();
  ASSERT_EQ(test::run_tetrasand(fmt::format("sim '{}' -o '{}' --cpu --duration 0.005",
                                            test::asset("scenes/prop_drop.toml").string(), out.string()),
                                &output),
            0)
      << output;
  EXPECT_NE(output.find(", 360 grains, "), std::string::npos) << output;
  EXPECT_NE(output.find("bodies: 360 grains; props: 1 dynamic; smooth walls: 5 planes\n"), std::string::npos)
      << output;
  EXPECT_NE(output.find((out / "metrics.csv").string() + " (2 rows), " +
                        (out / "particles_NNNNNN.ply").string() + " (2 files)\n"),
            std::string::npos)
      << output;
}

}  // namespace
}  // namespace ts::sim
