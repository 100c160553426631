#include "scene/scene.h"
#include "scene/scene_world.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>

#include "core/error.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

const char* const kMinimal = test::kMinimalScene;

// The InputError message of parsing `text`, or "" when it parses.
std::string parse_error(const std::string& text) {
  try {
    parse_scene(text, "scene.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Scene, MinimalSceneParsesWithDefaults) {
  const Scene s = parse_scene(kMinimal, "scene.toml");
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_DOUBLE_EQ(s.materials[0].youngs_modulus, 1e7);
  EXPECT_DOUBLE_EQ(s.grains.at(0).edge, 2e-3);
  EXPECT_EQ(s.simulation.dt, 0.0);  // auto
  EXPECT_EQ(s.gravity, Eigen::Vector3d(0, 0, -9.81));
}

TEST(Scene, ErrorsNameFileLineAndKey) {
  std::string text = kMinimal;
  text.replace(text.find("E = 1.0e7"), 9, "E = -5.0");
  EXPECT_EQ(parse_error(text), "scene.toml:4: material.E: must be > 0 (Pa)");
}

TEST(Scene, UnknownKeyIsRejectedWithASuggestion) {
  std::string text = kMinimal;
  text.replace(text.find("mu = 0.5"), 8, "mu = 0.5\nfricton = 0.4");
  const std::string error = parse_error(text);
  EXPECT_NE(error.find("scene.toml:8: material.fricton: unknown key"), std::string::npos) << error;
  // Top-level typos too.
  const std::string top = parse_error(std::string(kMinimal) + "\n[simulaton]\nduration = 1.0\n");
  EXPECT_NE(top.find("simulaton: unknown key (did you mean \"simulation\"?)"), std::string::npos) << top;
}

// A misspelt required key is the user's typo, not an absent key: the message points at its line.
TEST(Scene, MisspeltRequiredKeyIsReportedAsTheUnknownKeyWithTheSuggestion) {
  std::string text = kMinimal;
  text.replace(text.find("radius = 1.0e-3"), 6, "raduis");
  EXPECT_EQ(parse_error(text),
            "scene.toml:11: grain.raduis: unknown key (did you mean \"radius\"? grain.radius is required)");
  std::string table = kMinimal;
  table.replace(table.find("[grain]"), 7, "[grian]");
  const std::string error = parse_error(table);
  EXPECT_NE(error.find("grian: unknown key (did you mean \"grain\"? grain is required"), std::string::npos) << error;
  // Far from every required key, it stays "missing".
  std::string absent = kMinimal;
  absent.replace(absent.find("radius = 1.0e-3"), 15, "");
  EXPECT_NE(parse_error(absent).find("grain.radius: missing (required)"), std::string::npos) << parse_error(absent);
}

TEST(Scene, SyntaxErrorNamesTheLine) {
  const std::string error = parse_error(std::string(kMinimal) + "[simulation\n");
  EXPECT_EQ(error.rfind("scene.toml:13:", 0), 0u) << error;
}

TEST(Scene, BadValuesAreRejected) {
  const std::string base = kMinimal;
  EXPECT_NE(parse_error(base + "[simulation]\ndt = \"fast\"\n").find("simulation.dt: must be a time step"),
            std::string::npos);
  EXPECT_NE(parse_error(base + "[simulation]\nnormal_damping = \"hertz\"\n").find("not one of: tsuji, thesis"),
            std::string::npos);
  EXPECT_NE(parse_error(base + "[[boundary]]\ntype = \"plane\"\nmaterial = \"rock\"\n").find("no [[material]] named"),
            std::string::npos);
  EXPECT_NE(parse_error(base + "[[emitter]]\ntype = \"fill\"\nmin = [0, 0, 0]\nmax = [1, 1]\ncount = 3\n")
                .find("scene.toml:16: emitter.max: must be an array of 3 numbers"),
            std::string::npos);
  std::string no_grain = base.substr(0, base.find("[grain]"));
  EXPECT_NE(parse_error(no_grain).find("grain: missing (required; a [grain] table"), std::string::npos)
      << parse_error(no_grain);
}

TEST(Scene, FillEmitterPlacesGrainsWithoutOverlap) {
  const Scene s = parse_scene(std::string(kMinimal) +
                                  "[[emitter]]\ntype = \"fill\"\nmin = [0, 0, 0]\nmax = [0.03, 0.03, 0.03]\ncount = 100\n",
                              "scene.toml");
  const World w = make_world(s);
  ASSERT_EQ(w.bodies.size(), 100u);
  for (std::size_t a = 0; a < w.bodies.size(); ++a) {
    for (std::size_t b = a + 1; b < w.bodies.size(); ++b) {
      ASSERT_GT((w.bodies.position[a] - w.bodies.position[b]).norm(),
                w.bodies.bounding_radius[a] + w.bodies.bounding_radius[b]);
    }
    EXPECT_TRUE((w.bodies.position[a].array() >= w.bodies.bounding_radius[a]).all());
  }
}

TEST(Scene, FillRegionTooSmallNamesTheEmitter) {
  const Scene s = parse_scene(std::string(kMinimal) +
                                  "[[emitter]]\ntype = \"fill\"\nmin = [0, 0, 0]\nmax = [0.01, 0.01, 0.01]\ncount = 100\n",
                              "scene.toml");
  try {
    make_world(s);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.toml:13: emitter.count: the region holds only 8 grains"),
              std::string::npos)
        << e.what();
  }
}

TEST(Scene, RoughFloorWithHoleIsAStaticLattice) {
  const Scene s = parse_scene(std::string(kMinimal) + R"(
[[boundary]]
type = "plane"
rough = true
size = [0.02, 0.02]
hole_radius = 0.004
particle_radius = 1.0e-3
material = "sand"
)",
                              "scene.toml");
  const World w = make_world(s);
  ASSERT_EQ(w.bodies.size(), 1u);
  EXPECT_EQ(w.bodies.motion[0], MotionType::Static);
  EXPECT_EQ(w.bodies.inverse_mass[0], 0.0);
  const auto positions = particle_positions(w);
  // 11 x 11 lattice, minus the particles reaching into the 4 mm hole.
  EXPECT_LT(positions.size(), 121u);
  EXPECT_GT(positions.size(), 90u);
  for (const auto& p : positions) {
    EXPECT_NEAR(p.z(), -1e-3, 1e-15);  // tops of the spheres at the plane
    EXPECT_GE(p.head<2>().norm() + 1e-12, 0.004 + 1e-3);
  }
}

TEST(Scene, RoundHoleRimMakesTheOpeningADiscOfTheHoleDiameter) {
  const double hole = 0.004, r = 1e-3;
  const auto text = [&](std::string_view rim) {
    return std::string(kMinimal) + fmt::format(R"(
[[boundary]]
type = "plane"
rough = true
size = [0.02, 0.02]
hole_radius = {}
hole_rim = "{}"
particle_radius = {}
material = "sand"
)", hole, rim, r);
  };
  // Seen from above at the spheres' equator: the largest empty disc around the axis (the nearest sphere
  // edge), and the farthest reach of the opening along 3600 rays (where a ray first meets a sphere).
  const auto opening = [&](const World& w) {
    const auto positions = particle_positions(w);
    double nearest = 1e9, farthest = 0;
    for (const auto& c : positions) nearest = std::min(nearest, c.head<2>().norm() - r);
    for (int k = 0; k < 3600; ++k) {
      const Eigen::Vector2d dir(std::cos(k * std::numbers::pi / 1800), std::sin(k * std::numbers::pi / 1800));
      double hit = 1e9;
      for (const auto& c : positions) {
        const double along = c.head<2>().dot(dir), across2 = c.head<2>().squaredNorm() - along * along;
        if (along > 0 && across2 < r * r) hit = std::min(hit, along - std::sqrt(r * r - across2));
      }
      farthest = std::max(farthest, hit);
    }
    return std::pair{nearest, farthest};
  };
  const auto [lattice_near, lattice_far] = opening(make_world(parse_scene(text("lattice"), "scene.toml")));
  const World round = make_world(parse_scene(text("round"), "scene.toml"));
  const auto [round_near, round_far] = opening(round);
  EXPECT_NEAR(round_near, hole, 1e-12);
  EXPECT_LT(round_far, hole + 0.14 * r);  // bumps between rim spheres of at most 0.134 r
  EXPECT_GT(lattice_far, hole + 0.5 * r);  // the lattice's edge is ragged by a good part of a spacing
  EXPECT_GE(lattice_near + 1e-12, hole);
  ASSERT_EQ(round.bodies.size(), 1u);  // the rim belongs to the plate's static body
  for (const auto& p : particle_positions(round)) EXPECT_NEAR(p.z(), -r, 1e-15);
  try {
    parse_scene(std::string(kMinimal) + R"(
[[boundary]]
type = "plane"
rough = true
size = [0.02, 0.02]
hole_rim = "round"
particle_radius = 1.0e-3
material = "sand"
)", "scene.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hole_rim: needs a hole_radius > 0"), std::string::npos) << e.what();
  }
}

TEST(Scene, RoughCylinderLinesTheWallFromOutside) {
  const Scene s = parse_scene(std::string(kMinimal) + R"(
[[boundary]]
type = "cylinder"
rough = true
centre = [0.1, 0.0]
radius = 0.01
z_min = 0.0
z_max = 0.01
particle_radius = 5.0e-4
material = "sand"
)",
                              "scene.toml");
  const World w = make_world(s);
  ASSERT_EQ(w.bodies.size(), 1u);
  for (const auto& p : particle_positions(w)) {
    // Inner surface of the particle ring at the wall radius.
    EXPECT_NEAR((p.head<2>() - Eigen::Vector2d(0.1, 0)).norm() - 5e-4, 0.01, 1e-12);
    EXPECT_GE(p.z(), -1e-15);
    EXPECT_LE(p.z(), 0.01 + 1e-15);
  }
}

TEST(Scene, ColumnEmitterStacksGrainsInsideItsRadius) {
  const Scene s = parse_scene(std::string(kMinimal) + R"(
[[emitter]]
type = "column"
centre = [0.0, 0.0, 0.01]
radius = 0.012
count = 60
)",
                              "scene.toml");
  const World w = make_world(s);
  ASSERT_EQ(w.bodies.size(), 60u);
  for (std::size_t b = 0; b < w.bodies.size(); ++b) {
    EXPECT_LE(w.bodies.position[b].head<2>().norm() + w.bodies.bounding_radius[b], 0.012 + 1e-12);
    EXPECT_GE(w.bodies.position[b].z() - w.bodies.bounding_radius[b], 0.01 - 1e-12);
  }
}

TEST(Scene, SmoothBoxIsFiveInwardPlanes) {
  const Scene s = parse_scene(
      std::string(kMinimal) + "[[boundary]]\ntype = \"box\"\nmin = [0, 0, 0]\nmax = [1, 2, 3]\nmaterial = \"sand\"\n",
      "scene.toml");
  const World w = make_world(s);
  ASSERT_EQ(w.walls.planes.size(), 5u);
  const Eigen::Vector3d inside(0.5, 1, 1);
  for (const PlaneWall& p : w.walls.planes) EXPECT_GT(p.normal.dot(inside - p.point), 0.4);
}

TEST(Scene, BundledScenesLoadAndBuild) {
  for (const char* name : {"free_fall", "two_grain_collision", "pile", "hourglass"}) {
    const Scene s = load_scene(test::asset(std::string("scenes/") + name + ".toml"));
    const World w = make_world(s);
    const TimeStepBound bound = scene_time_step_bound(s, w);
    EXPECT_GT(bound.recommended, 0) << name;
    if (s.simulation.dt > 0) {
      EXPECT_EQ(check_time_step(s.simulation.dt, bound), "") << name;
    }
  }
}

TEST(Scene, PourEmitterReleasesGrainsAtItsRate) {
  Scene s = load_scene(test::asset("scenes/pile.toml"));
  World w = make_world(s);
  const std::size_t floor_bodies = w.bodies.size();
  PourEmitter pour(s, s.emitters.at(0));
  w.time = 0.0;
  EXPECT_EQ(pour.emit(w), 1u);
  w.time = 4.0e-3;  // 2000 grains/s: 9 grains due by now
  EXPECT_EQ(pour.emit(w), 8u);
  EXPECT_EQ(w.bodies.size(), floor_bodies + 9);
  EXPECT_FALSE(pour.finished());
}

TEST(Scene, TimeStepAboveTheBoundWarns) {
  Scene s = parse_scene(std::string(kMinimal) + "[simulation]\ndt = 1.0e-3\n", "scene.toml");
  const World w = make_world(s);
  const TimeStepBound bound = scene_time_step_bound(s, w);
  const std::string warning = check_time_step(s.simulation.dt, bound);
  EXPECT_NE(warning.find("exceeds the stable bound"), std::string::npos) << warning;
  EXPECT_NE(warning.find(fmt::format("{:.3g}", bound.recommended)), std::string::npos) << warning;
}

// A cube of 8 particles written the way the sampler writes bodies.
std::filesystem::path write_cube_body(const std::filesystem::path& dir) {
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
                    "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n";
  for (int i = 0; i < 8; ++i) {
    const float v[6] = {float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1), 0, 0, 1};
    ply.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  std::ofstream(dir / "cube.particles.ply", std::ios::binary) << ply;
  std::ofstream(dir / "cube.body.json") << R"({"particle_radius": 0.1, "particle_count": 8,
    "particles": "cube.particles.ply", "mass": 2.0, "center_of_mass": [0.5, 0.5, 0.5],
    "inertia": [[0.5, 0, 0], [0, 0.5, 0], [0, 0, 0.5]]})";
  return dir / "cube.body.json";
}

TEST(Scene, PropsComeFromBodyFilesWithTheirPose) {
  const auto dir = test::temp_dir();
  write_cube_body(dir);
  const std::string text = std::string(kMinimal) + R"(
[[prop]]
body = "cube.body.json"
position = [1.0, 0.0, 0.0]
orientation = [0.7071067811865476, 0.0, 0.0, 0.7071067811865476]
motion = "dynamic"
material = "sand"
)";
  const Scene s = parse_scene(text, dir / "scene.toml");
  const World w = make_world(s);
  ASSERT_EQ(w.bodies.size(), 1u);
  EXPECT_DOUBLE_EQ(w.bodies.inverse_mass[0], 0.5);
  EXPECT_TRUE(w.bodies.inverse_inertia[0].isApprox(2.0 * Eigen::Matrix3d::Identity()));
  // The mesh's (1, 0, 0) corner, turned 90 degrees about z and moved by (1, 0, 0), lands at (1, 1, 0).
  const auto positions = particle_positions(w);
  EXPECT_LT((positions[1] - Eigen::Vector3d(1, 1, 0)).norm(), 1e-12);
  EXPECT_LT((w.bodies.position[0] - Eigen::Vector3d(0.5, 0.5, 0.5)).norm(), 1e-12);
  // A body file with a missing key names it.
  std::ofstream(dir / "cube.body.json") << R"({"particle_radius": 0.1, "particles": "cube.particles.ply"})";
  try {
    make_world(s);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cube.body.json: mass: missing"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ts::scene

namespace ts::scene {
namespace {

TEST(Scene, ResortPeriodIsReadAndMustNotBeNegative) {
  const std::string base = std::string(kMinimal) + "\n[simulation]\n";
  EXPECT_EQ(parse_scene(base + "resort_every = 25\n", "scene.toml").simulation.step.resort_every, 25);
  EXPECT_EQ(parse_scene(base, "scene.toml").simulation.step.resort_every, 100);  // the default
  EXPECT_NE(parse_error(base + "resort_every = -1\n").find("scene.toml:15: simulation.resort_every: must be >= 0"),
            std::string::npos)
      << parse_error(base + "resort_every = -1\n");
}

// Symplectic Euler meets the 2 % restitution target at the automatic step; forward Euler (the thesis's)
// needs a step about 20x smaller, so a scene without the key must not get it.
TEST(Scene, SceneWithoutIntegratorKeyIsSymplecticAndEulerStaysAnOption) {
  EXPECT_EQ(parse_scene(kMinimal, "scene.toml").simulation.step.integrator, Integrator::SemiImplicitEuler);
  const std::string base = std::string(kMinimal) + "\n[simulation]\n";
  EXPECT_EQ(parse_scene(base, "scene.toml").simulation.step.integrator, Integrator::SemiImplicitEuler);
  EXPECT_EQ(parse_scene(base + "integrator = \"euler\"\n", "scene.toml").simulation.step.integrator,
            Integrator::ForwardEuler);
}

}  // namespace
}  // namespace ts::scene
