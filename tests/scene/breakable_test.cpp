// Breakable props in scene files (issue 48): [[bond_material]] and the breakable, bond_material,
// bind_to and bind_material keys of [[prop]], the world a breakable prop becomes (a sphere body per
// particle of its `--fill` body, bonds between neighbours, bound to another prop), the bonds' share of
// the time step, fragments, metrics.csv, and the bundled crumble and scrape scenes on the CPU reference.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>
#include <vector>
#include <string>

#include "body/body_file.h"
#include "core/error.h"
#include "export/lammps_deck.h"
#include "scene/fragments.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

namespace fs = std::filesystem;

// s: the bundled scenes cut short for the suite, just past where their bonds first break (the ball
// lands at about 0.27 s; the scraper reaches the layer at about 0.015 s).
constexpr double kCrumbleTestDuration = 0.31;
constexpr double kScrapeTestDuration = 0.03;

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A bundled scene's text with each `from` replaced by its `to` (each must be there), parsed as if it
// stood in assets/scenes (so its bodies resolve).
std::string scene_text(const std::string& name, const std::vector<std::pair<std::string, std::string>>& edits = {}) {
  std::string text = read_text(test::asset("scenes/" + name));
  for (const auto& [from, to] : edits) {
    const std::size_t at = text.find(from);
    if (at == std::string::npos) ADD_FAILURE() << "no \"" << from << "\" in " << name;
    else text.replace(at, from.size(), to);
  }
  return text;
}

std::string parse_error(const std::string& text) {
  try {
    parse_scene(text, test::asset("scenes/edited.toml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The line of the first occurrence of `needle` in `text`, from 1.
int line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

TEST(BreakableProps, BadBondMaterialValuesNameFileLineAndKey) {
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"tensile_strength = 1.0e4", "tensile_strength = 0.0", "bond_material.tensile_strength: must be > 0 Pa"},
      {"shear_strength = 1.0e4", "shear_strength = -1.0", "bond_material.shear_strength: must be > 0 Pa"},
      {"tensile_strength = 1.0e4", "tensile_strength = inf", "bond_material.tensile_strength: must be finite"},
      {"strength_spread = 0.3", "strength_spread = -0.1", "bond_material.strength_spread: must be in [0, 1]"},
      {"E = 1.0e6               #", "E = nan #", "bond_material.E: must be finite"},
      {"E = 1.0e6               #", "E = -1.0 #", "bond_material.E: must be > 0 Pa"},
      {"bond_distance = 1.2", "bond_distance = 0.9", "bond_material.bond_distance: must be in [1, 2]"},
      {"radius_factor = 1.0", "radius_factor = 1.5", "bond_material.radius_factor: must be in (0, 1]"},
      {"seed = 7", "seed = -7", "bond_material.seed: must be >= 0"},
      {"seed = 7", "seed = 7\ncolour = 1", "bond_material.colour: unknown key"},
  };
  for (const auto& [from, to, expected] : cases) {
    const std::string text = scene_text("crumble.toml", {{from, to}});
    const std::string error = parse_error(text);
    const std::string where = fmt::format("edited.toml:{}: {}", line_of(text, to.substr(to.rfind('\n') + 1)), expected);
    EXPECT_NE(error.find(where), std::string::npos) << to << "\n" << error;
  }
}

TEST(BreakableProps, PropKeysNameWhatIsMissingOrWrong) {
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"bond_material = \"dry clay\"", "bond_material = \"wet clay\"",
       "prop.bond_material: no [[bond_material]] named \"wet clay\" (have: \"dry clay\")"},
      {"bond_material = \"dry clay\"", "", "prop.bond_material: missing (required)"},
      {"bond_material = \"dry clay\"", "bond_material = \"dry clay\"\nbind_material = \"dry clay\"",
       "prop.bind_material: binds the prop to the prop named by bind_to: add bind_to"},
      {"bond_material = \"dry clay\"", "bond_material = \"dry clay\"\nbind_to = \"floor\"\nbind_material = \"dry clay\"",
       "prop.bind_to: no other [[prop]] named \"floor\" (the scene has no other prop)"},
      {"motion = \"dynamic\"", "motion = \"static\"", "prop.breakable: a breakable prop moves as its spheres do"},
      {"breakable = true", "breakable = false", "prop.bond_material: only a breakable prop has bonds"},
      {"[simulation]", "[simulation]\nintegrator = \"euler\"",
       "simulation.integrator: \"euler\" cannot run a breakable prop"},
      {"[output]", "[output.camera]\nfollow = \"prop ball\"\neye = [0.5, 0.0, 0.5]\n\n[output]",
       "output.camera.follow: \"prop ball\" is breakable"},
  };
  for (const auto& [from, to, expected] : cases) {
    const std::string error = parse_error(scene_text("crumble.toml", {{from, to}}));
    EXPECT_NE(error.find(expected), std::string::npos) << to << "\n" << error;
  }
}

TEST(BreakableProps, BodyWithoutInteriorParticlesIsRefusedAskingForFill) {
  const std::string text = scene_text("crumble.toml", {{"../bodies/sphere.body.json", "../bodies/cube.body.json"}});
  const std::string error = parse_error(text);
  EXPECT_NE(error.find(fmt::format("edited.toml:{}: prop.breakable: ", line_of(text, "breakable = true"))),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("cube.body.json has no interior particles"), std::string::npos) << error;
  EXPECT_NE(error.find("--fill"), std::string::npos) << error;
}

TEST(BreakableProps, EachParticleBecomesASphereBodyKeepingTheBodysMassAndCentre) {
  const Scene scene = load_scene(test::asset("scenes/crumble.toml"));
  const body::ParticleBody ball = body::read_body(test::asset("bodies/sphere.body.json"), body::BodyKeys::Physical);
  ASSERT_GT(ball.interior_count, 0u);
  WorldSources sources;
  const World world = make_world(scene, &sources);
  const std::vector<BodyRange> ranges = prop_body_ranges(scene, world);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_TRUE(ranges[0].breakable);
  EXPECT_EQ(ranges[0].first, sources.prop_bodies[0]);
  ASSERT_EQ(ranges[0].count, ball.positions.size());
  double mass = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (std::uint32_t b = ranges[0].first; b < ranges[0].first + ranges[0].count; ++b) {
    ASSERT_EQ(world.bodies.particle_count[b], 1u);
    EXPECT_EQ(world.bodies.motion[b], MotionType::Dynamic);
    const double m = 1 / world.bodies.inverse_mass[b];
    const double r = world.particles.radius[world.bodies.first_particle[b]];
    EXPECT_TRUE(world.bodies.inverse_inertia[b].isApprox(Eigen::Matrix3d::Identity() / (0.4 * m * r * r)));
    mass += m;
    moment += m * world.bodies.position[b];
  }
  EXPECT_NEAR(mass, ball.mass, 1e-9 * ball.mass);
  const Eigen::Vector3d centre = scene.props[0].position + ball.center_of_mass;
  EXPECT_LT((moment / mass - centre).norm(), 1e-9);
  // Bonds join the ball's spheres only, of its one bond material, all intact.
  ASSERT_GT(world.bonds.size(), ball.positions.size());
  EXPECT_EQ(world.bonds.intact_count(), world.bonds.size());
  ASSERT_EQ(world.bond_materials.size(), 1u);
  EXPECT_EQ(world.bond_materials[0], scene.bond_materials[0].material);
  const std::uint32_t first = world.bodies.first_particle[ranges[0].first];
  for (std::size_t k = 0; k < world.bonds.size(); ++k) {
    EXPECT_GE(world.bonds.a[k], first);
    EXPECT_LT(world.bonds.b[k], first + ranges[0].count);
  }
  // Its spheres are props, not grains: the emitter's 360 grains come after them.
  EXPECT_EQ(fixture_bodies(scene, world), ranges[0].first + ranges[0].count);
  EXPECT_EQ(world.bodies.size() - fixture_bodies(scene, world), 360u);
  EXPECT_EQ(sources.bodies.size(), fixture_bodies(scene, world));
}

TEST(BreakableProps, BindToBondsTheLayerToTheOtherPropWithTheBindMaterial) {
  const Scene scene = load_scene(test::asset("scenes/scrape.toml"));
  const World world = make_world(scene);
  const std::vector<BodyRange> ranges = prop_body_ranges(scene, world);
  ASSERT_EQ(ranges.size(), 3u);
  const std::uint32_t plate_first = world.bodies.first_particle[ranges[0].first];
  const std::uint32_t plate_end = plate_first + world.bodies.particle_count[ranges[0].first];
  const std::uint32_t layer_first = world.bodies.first_particle[ranges[1].first];
  const std::uint32_t layer_end = layer_first + ranges[1].count;
  std::size_t crust = 0, glue = 0;
  for (std::size_t k = 0; k < world.bonds.size(); ++k) {
    const std::uint32_t a = world.bonds.a[k], b = world.bonds.b[k];
    ASSERT_LT(a, b);
    if (world.bonds.material[k] == 0) {
      ++crust;
      EXPECT_TRUE(a >= layer_first && b < layer_end);
    } else {
      ++glue;
      EXPECT_EQ(world.bonds.material[k], 1);
      EXPECT_TRUE(a >= plate_first && a < plate_end && b >= layer_first && b < layer_end) << a << " " << b;
      // Within the glue's bond distance.
      const auto x = particle_positions(world);
      EXPECT_LT((x[a] - x[b]).norm(),
                1.3 * (world.particles.radius[a] + world.particles.radius[b]) * (1 + 1e-12));
    }
  }
  EXPECT_GT(crust, 0u);
  EXPECT_GT(glue, 0u);
  EXPECT_EQ(find_fragments(world, ranges).count, 1u);  // the glue joins no fragment: one layer
}

TEST(BreakableProps, TimeStepBoundCountsTheBondsAndRefusesBondsTooStiffToStep) {
  const Scene scene = load_scene(test::asset("scenes/crumble.toml"));
  const World world = make_world(scene);
  const TimeStepBound bound = scene_time_step_bound(scene, world);
  ASSERT_TRUE(std::isfinite(bound.bonds));
  EXPECT_LE(bound.recommended, bound.bonds);
  EXPECT_EQ(bound.bonds, scene_bond_time_step(world).step);
  // Stiffer bonds set the step; far stiffer ones are refused naming the bond material's E.
  const std::string stiff = scene_text("crumble.toml", {{"E = 1.0e6               #", "E = 1.0e9 #"}});
  const Scene stiff_scene = parse_scene(stiff, test::asset("scenes/stiff.toml"));
  const TimeStepBound stiff_bound = scene_time_step_bound(stiff_scene, make_world(stiff_scene));
  EXPECT_EQ(limiting_bound(stiff_bound), "bonds");
  EXPECT_EQ(stiff_bound.recommended, stiff_bound.bonds);
  const std::string rigid = scene_text("crumble.toml", {{"E = 1.0e6               #", "E = 1.0e16 #"}});
  const Scene rigid_scene = parse_scene(rigid, test::asset("scenes/rigid.toml"));
  try {
    scene_time_step_bound(rigid_scene, make_world(rigid_scene));
    FAIL() << "a bond step below 1e-9 s was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("rigid.toml:{}: bond_material.E: ", line_of(rigid, "[[bond_material]]"))),
              std::string::npos)
        << e.what();
  }
}

TEST(BreakableProps, FragmentsAreTheGroupsIntactBondsJoin) {
  const Scene scene = load_scene(test::asset("scenes/crumble.toml"));
  World world = make_world(scene);
  const std::vector<BodyRange> ranges = prop_body_ranges(scene, world);
  const Fragments whole = find_fragments(world, ranges);
  EXPECT_EQ(whole.count, 1u);
  const body::ParticleBody ball = body::read_body(test::asset("bodies/sphere.body.json"), body::BodyKeys::Physical);
  EXPECT_NEAR(whole.largest_mass, ball.mass, 1e-9 * ball.mass);
  EXPECT_EQ(whole.label[world.particles.size() - 1], Fragments::kNone);  // a grain's particle
  // Every bond broken: each sphere is its own fragment, the heaviest sphere the largest.
  std::fill(world.bonds.intact.begin(), world.bonds.intact.end(), std::uint8_t{0});
  const Fragments apart = find_fragments(world, ranges);
  EXPECT_EQ(apart.count, ranges[0].count);
  double heaviest = 0;
  for (std::uint32_t b = ranges[0].first; b < ranges[0].first + ranges[0].count; ++b)
    heaviest = std::max(heaviest, 1 / world.bodies.inverse_mass[b]);
  EXPECT_DOUBLE_EQ(apart.largest_mass, heaviest);
}

TEST(BreakableProps, LammpsExportRefusesABreakableProp) {
  const Scene scene = load_scene(test::asset("scenes/crumble.toml"));
  try {
    exporter::export_lammps(scene, test::temp_dir() / "deck");
    FAIL() << "exported";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a breakable prop"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("BPM"), std::string::npos) << e.what();
  }
}

// The metrics.csv columns of a run's bonds: the last row's, by name.
std::map<std::string, double> last_row(const fs::path& csv) {
  std::istringstream text(read_text(csv));
  std::string header, line, last;
  std::getline(text, header);
  while (std::getline(text, line)) last = line;
  std::map<std::string, double> row;
  std::istringstream names(header), values(last);
  for (std::string name, value; std::getline(names, name, ',') && std::getline(values, value, ',');)
    row[name] = std::stod(value);
  return row;
}

void expect_bonds_break(const std::string& name, double duration, std::size_t fragments_at_least) {
  const Scene scene = load_scene(test::asset("scenes/" + name));
  const fs::path out = test::temp_dir() / name;
  RunControl control;
  control.duration = duration;
  const RunResult result = run_scene(scene, out, {}, {}, control);
  EXPECT_GT(result.bonds_at_start, 0u) << name;
  EXPECT_GT(result.bonds.broken, 0u) << name;
  EXPECT_EQ(result.bonds.intact + result.bonds.broken, result.bonds_at_start) << name;
  EXPECT_GE(result.bonds.fragments, fragments_at_least) << name;
  const std::map<std::string, double> row = last_row(out / "metrics.csv");
  EXPECT_EQ(row.at("bonds"), static_cast<double>(result.bonds.intact)) << name;
  EXPECT_EQ(row.at("bonds_broken"), static_cast<double>(result.bonds.broken)) << name;
  EXPECT_EQ(row.at("fragments"), static_cast<double>(result.bonds.fragments)) << name;
  EXPECT_NEAR(row.at("largest_fragment_kg"), result.bonds.largest_fragment_mass,
              1e-8 * result.bonds.largest_fragment_mass) << name;
  // fragments.csv: every fragment at the end, heaviest first, the first the largest.
  std::istringstream pieces(read_text(out / "fragments.csv"));
  std::string line;
  std::getline(pieces, line);
  EXPECT_EQ(line, "label,spheres,mass_kg") << name;
  std::vector<double> masses;
  std::size_t spheres = 0;
  while (std::getline(pieces, line)) {
    const std::size_t first = line.find(','), second = line.find(',', first + 1);
    spheres += std::stoul(line.substr(first + 1, second - first - 1));
    masses.push_back(std::stod(line.substr(second + 1)));
  }
  ASSERT_EQ(masses.size(), result.bonds.fragments) << name;
  EXPECT_NEAR(masses.front(), result.bonds.largest_fragment_mass, 1e-8 * masses.front()) << name;
  EXPECT_TRUE(std::is_sorted(masses.rbegin(), masses.rend())) << name;
  EXPECT_GE(spheres, masses.size()) << name;
}

TEST(BreakableProps, CrumbleSceneBreaksTheBallIntoFragmentsOnLanding) {
  expect_bonds_break("crumble.toml", kCrumbleTestDuration, 2);
}

TEST(BreakableProps, ScrapeSceneBreaksBondsWhereTheToolMeetsTheLayer) {
  expect_bonds_break("scrape.toml", kScrapeTestDuration, 1);
}

}  // namespace
}  // namespace ts::scene
