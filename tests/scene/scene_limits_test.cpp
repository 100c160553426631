// Sizes checked before allocation (scene/scene_limits.h): every count a scene's keys imply is refused
// with file:line:key and the largest that fits before anything is allocated, in sim and in export.
#include "scene/scene_limits.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "body/body_file.h"
#include "body/particles_ply.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "export/lammps_deck.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

namespace fs = std::filesystem;

const std::string kHead = std::string("gravity = [0.0, 0.0, -9.81]\n") + test::kMinimalScene;

// A fill or pour emitter from the origin to `max` (min given last, as it seldom changes).
std::string box_emitter(const std::string& type, const std::string& max, long long count,
                        const std::string& extra = "", const std::string& min = "[0.0, 0.0, 0.0]") {
  return test::box_emitter(type, min, max, count, extra);
}

std::string column_emitter(const std::string& radius, long long count) {
  return fmt::format("[[emitter]]\ntype = \"column\"\ncentre = [0.0, 0.0, 0.0]\nradius = {}\ncount = {}\n", radius,
                     count);
}

// Writes kHead + `tables` as DIR/scene.toml; returns make_world's InputError message ("" if none).
std::string world_error(const fs::path& dir, const std::string& tables) {
  write_file_atomically(dir / "scene.toml", kHead + tables);
  try {
    make_world(load_scene(dir / "scene.toml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The message starts with "DIR/scene.toml:LINE: KEY:" and says what fits.
void expect_names(const std::string& message, const fs::path& dir, int line, const std::string& key,
                  const std::string& fits) {
  EXPECT_EQ(message.rfind(fmt::format("{}:{}: {}:", (dir / "scene.toml").string(), line, key), 0), 0u)
      << message;
  EXPECT_NE(message.find(fits), std::string::npos) << message;
}

constexpr int kFirstTable = 14;  // the line of the first table after kHead

TEST(SceneLimits, EmitterBoxAGigametreWideIsRefusedInSimAndExport) {
  const fs::path dir = test::temp_dir();
  const std::string fill = box_emitter("fill", "[1e9, 0.01, 0.01]", 8);
  expect_names(world_error(dir, fill), dir, kFirstTable, "emitter.max", "at most 134217728 fit");
  // The same through the runner and the LAMMPS export (both used to end in vector::reserve).
  const Scene scene = load_scene(dir / "scene.toml");
  EXPECT_THROW(run_scene(scene, dir / "out"), InputError);
  try {
    exporter::export_lammps(scene, dir / "deck");
    FAIL() << "exported";
  } catch (const InputError& e) {
    expect_names(e.what(), dir, kFirstTable, "emitter.max", "at most 134217728 fit");
  }
  const std::string pour = box_emitter("pour", "[1e9, 1e9, 1e9]", 8, "rate = 10.0\n");
  expect_names(world_error(dir, pour), dir, kFirstTable, "emitter.max", "a box of at most");
  // A large box within the limit is no error (2 m x 2 m x 2 cm: 6.7e5 sites).
  const std::string fits = box_emitter("fill", "[2.0, 2.0, 0.02]", 8);
  EXPECT_EQ(world_error(dir, fits), "");
}

TEST(SceneLimits, GrainCountsAndColumnsBeyondTheLimitsAreRefused) {
  const fs::path dir = test::temp_dir();
  const std::string many = box_emitter("fill", "[0.1, 0.1, 0.1]", 300000000);
  expect_names(world_error(dir, many), dir, kFirstTable, "emitter.count", "at most 268435456 grains fit");
  const std::string wide = column_emitter("1e5", 10);
  expect_names(world_error(dir, wide), dir, kFirstTable, "emitter.radius", "at most 134217728 fit");
  const std::string tall = column_emitter("0.02", 200000000);
  expect_names(world_error(dir, tall), dir, kFirstTable, "emitter.count", "at most 134217728 fit");
  // Two emitters each within the limit, together beyond it.
  const std::string one = box_emitter("pour", "[0.1, 0.1, 0.1]", 200000000, "rate = 10.0\n");
  const std::string two = one + one;
  const std::string total = world_error(dir, two);
  EXPECT_EQ(total.rfind((dir / "scene.toml").string() + ": the scene needs 1.6e+09 particles", 0), 0u)
      << total;
  EXPECT_NE(total.find("at most 1073741824 fit"), std::string::npos) << total;
}

TEST(SceneLimits, RoughBoundariesBeyondTheLimitAreRefused) {
  const fs::path dir = test::temp_dir();
  const std::string rough = "rough = true\nparticle_radius = 1e-3\nmaterial = \"sand\"\n";
  expect_names(world_error(dir, "[[boundary]]\ntype = \"plane\"\nsize = [1e7, 1e7]\n" + rough), dir,
               kFirstTable, "boundary.size", "at most 1073741824 fit");
  expect_names(
      world_error(dir,
                  "[[boundary]]\ntype = \"box\"\nmin = [0.0, 0.0, 0.0]\nmax = [1e5, 1e5, 1.0]\n" + rough),
      dir, kFirstTable, "boundary.max", "at most 1073741824 fit");
  expect_names(
      world_error(dir, "[[boundary]]\ntype = \"cylinder\"\nradius = 0.1\nz_min = 0.0\nz_max = 1e9\n" + rough),
      dir, kFirstTable, "boundary.z_max", "at most 1073741824 fit");
  expect_names(world_error(dir,
                           "[[boundary]]\ntype = \"plane\"\nsize = [0.1, 0.1]\nhole_radius = 1e12\n"
                           "hole_rim = \"round\"\n" +
                               rough),
               dir, kFirstTable, "boundary.hole_radius", "at most 1073741824 fit");
}

TEST(SceneLimits, ParticlesFartherThanTheGridCellsReachAreRefused) {
  const fs::path dir = test::temp_dir();
  const std::string prop =
      fmt::format("[[prop]]\nbody = \"{}\"\nposition = [1e9, 0.0, 0.0]\nmaterial = \"sand\"\n",
                  test::asset("bodies/cube.body.json").string());
  const std::string message = world_error(dir, prop);
  expect_names(message, dir, kFirstTable, "prop.position", "at most 1e+09 cells fit");
  const std::string far = box_emitter("fill", "[-999999999999.9, 0.01, 0.01]", 1, "", "[-1e12, 0.0, 0.0]");
  expect_names(world_error(dir, far), dir, kFirstTable, "emitter.min", "at most 1e+09 cells fit");
}

// A body whose particle file puts one particle 1e38 m out (a float the file can hold) reaches as far as
// a prop placed there: refused naming the prop's body, before a grid coordinate overflows.
// A body whose particle lies beyond the grid's reach from its centre of mass is refused when the
// scene reads it (body/body_file.h kMaxBodyReachInDiameters), naming the body file, before any
// world is built around it.
TEST(SceneLimits, PropBodyWithAParticleFarBeyondTheGridIsRefused) {
  const fs::path dir = test::temp_dir();
  body::ParticleBody far = body::read_body(test::asset("bodies/cube.body.json"));
  const fs::path body = body::write_body(dir, "far", far);
  far.positions.at(0) = Eigen::Vector3f(1e38f, 0, 0);
  write_file_atomically(dir / "far.particles.ply", body::particles_ply_bytes(far.positions, far.normals));
  const std::string prop = fmt::format("[[prop]]\nbody = \"{}\"\nmaterial = \"sand\"\n", body.string());
  const std::string message = world_error(dir, prop);
  EXPECT_NE(message.find(body.string()), std::string::npos) << message;
  EXPECT_NE(message.find("particles: particle 0 lies 1e+38 m from the centre of mass"), std::string::npos)
      << message;
  EXPECT_NE(message.find("the simulator's grid reaches at most 1e+09"), std::string::npos) << message;
}

}  // namespace
}  // namespace ts::scene
