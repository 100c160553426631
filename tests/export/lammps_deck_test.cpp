// tetrasand export lammps: the deck's contents, its errors, and Debian's `lmp` running it to the same
// physical outcome as tetrasand's CPU reference (scripts/deps.sh installs lammps).
#include "export/lammps_deck.h"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "sim/grain.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "sim/cpu_stepper.h"
#include "sim/time_step.h"
#include "sim/world.h"
#include "tests/test_support.h"

namespace ts::exporter {
namespace {

namespace fs = std::filesystem;

// A scene file written into `dir` as scene.toml (the CLI test reads it from there).
Scene write_scene(const fs::path& dir, const std::string& text) {
  const fs::path file = dir / "scene.toml";
  write_file_atomically(file, text);
  return load_scene(file);
}

// The bed of assets/scenes/reference/bed.toml (shared with bench/peers) cut to 150 grains filled up to
// 6 cm and 0.35 s, so the CPU reference settles it in a few seconds: a smooth-walled box 2 cm wide,
// grains (r = 1 mm, E = 1 MPa) falling from a lattice onto its floor.
Scene bed_scene(const fs::path& dir) {
  Scene scene = write_scene(dir, read_file(test::asset("scenes/reference/bed.toml")));
  scene.emitters.at(0).count = 150;
  scene.emitters.at(0).max.z() = 0.06;
  scene.simulation.duration = 0.35;
  scene.output.ply = false;
  scene.output.csv = false;
  return scene;
}

// One nearly spherical grain dropped without spin onto a smooth floor
// (assets/scenes/reference/bounce.toml, symplectic Euler): its rebound measures the normal damping.
Scene bounce_scene(const fs::path& dir) {
  Scene scene = write_scene(dir, read_file(test::asset("scenes/reference/bounce.toml")));
  scene.output.ply = false;
  scene.output.csv = false;
  return scene;
}

// Runs the deck with Debian's lmp; fails the test with the log's tail when it does not finish.
void run_lammps(const LammpsDeck& deck) {
  const fs::path dir = deck.input.parent_path();
  const std::string cmd = "cd '" + dir.string() + "' && lmp -in in.tetrasand -log log.lammps -screen none";
  const int status = std::system(cmd.c_str());
  std::string log;
  if (fs::exists(dir / "log.lammps")) log = read_file(dir / "log.lammps");
  ASSERT_EQ(status, 0) << "lmp failed (is lammps installed? scripts/deps.sh):\n"
                       << log.substr(log.size() > 3000 ? log.size() - 3000 : 0);
}

// Frames of a LAMMPS custom dump "id mol type x y z radius": per frame, the mean height of each
// molecule's atoms (m), keyed by molecule.
std::vector<std::map<long, double>> dump_heights(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::map<long, double>> frames;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: NUMBER OF ATOMS", 0) != 0) continue;
    std::getline(in, line);
    const long n = std::stol(line);
    for (int k = 0; k < 5; ++k) std::getline(in, line);  // box bounds (4 lines) and the ATOMS header
    std::map<long, std::pair<double, int>> sums;
    for (long i = 0; i < n && std::getline(in, line); ++i) {
      std::istringstream row(line);
      long id = 0, mol = 0, type = 0;
      double x = 0, y = 0, z = 0;
      row >> id >> mol >> type >> x >> y >> z;
      sums[mol].first += z;
      sums[mol].second += 1;
    }
    std::map<long, double> frame;
    for (const auto& [mol, s] : sums) frame[mol] = s.first / s.second;
    frames.push_back(std::move(frame));
  }
  return frames;
}

double mean_grain_height(const World& world) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] != MotionType::Dynamic) continue;
    sum += world.bodies.position[b].z();
    ++n;
  }
  return sum / static_cast<double>(n);
}

// Atom positions of a LAMMPS custom dump "id mol type x y z radius" with one frame (final.dump):
// molecule -> its atoms' positions in id order.
std::map<long, std::vector<Eigen::Vector3d>> dump_atoms(const fs::path& file) {
  std::ifstream in(file);
  std::map<long, std::vector<Eigen::Vector3d>> atoms;
  std::string line;
  while (std::getline(in, line) && line.rfind("ITEM: ATOMS", 0) != 0) {
  }
  std::map<long, std::pair<long, Eigen::Vector3d>> by_id;  // id -> (mol, x)
  while (std::getline(in, line)) {
    std::istringstream row(line);
    long id = 0, mol = 0, type = 0;
    double x = 0, y = 0, z = 0;
    if (row >> id >> mol >> type >> x >> y >> z) by_id[id] = {mol, Eigen::Vector3d(x, y, z)};
  }
  for (const auto& [id, atom] : by_id) atoms[atom.first].push_back(atom.second);
  return atoms;
}

// A scene of one tetrahedral grain (r = 1 mm, E = 1 MPa) above a smooth floor, dt fixed.
Scene flight_scene(const fs::path& dir) {
  return write_scene(dir, R"(gravity = [0.0, 0.0, -9.81]
[[material]]
name = "sand"
E = 1.0e6
nu = 0.3
restitution = 0.5
mu = 0.5
gamma_s = 0.01
density = 2600.0
[grain]
radius = 1.0e-3
material = "sand"
[[emitter]]
type = "fill"
min = [-0.01, -0.01, 0.5]
max = [0.01, 0.01, 0.52]
count = 1
seed = 5
[[boundary]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "sand"
[simulation]
duration = 0.1
dt = 1.0e-5
[output]
every = 100
)");
}

TEST(ExportLammps, TsujiPolynomialInverseRoundTrips) {
  for (double e : {0.05, 0.3, 0.5, 0.65, 0.9}) {
    EXPECT_NEAR(lammps_restitution_for_alpha(lammps_tsuji_alpha(e)), e, 1e-9) << e;
  }
  EXPECT_NEAR(lammps_tsuji_alpha(0.0), 1.2728, 1e-12);
  EXPECT_THROW(lammps_restitution_for_alpha(1.5), InputError);
}

TEST(ExportLammps, DeckGivesExplicitBodyMassInertiaAndMatchedContactModel) {
  const fs::path dir = test::temp_dir();
  const Scene scene = bed_scene(dir);
  const LammpsDeck deck = export_lammps(scene, dir / "deck");
  EXPECT_EQ(deck.dynamic_bodies, 150u);
  EXPECT_EQ(deck.steps, static_cast<std::int64_t>(std::ceil(0.35 / deck.dt - 1e-9)));
  for (const fs::path& f : deck.files) EXPECT_TRUE(fs::exists(f)) << f;

  // Every body line carries the grain's mass and its isotropic inertia, whatever the orientation.
  const GrainShape g = make_tetrahedral_grain(1e-3, 2e-3, 2600.0);
  std::istringstream bodies(read_file(dir / "deck" / "bodies.rigid"));
  std::string line;
  while (std::getline(bodies, line) && line[0] == '#') {
  }
  EXPECT_EQ(std::stoul(line), 150u);
  int rows = 0;
  while (std::getline(bodies, line)) {
    std::istringstream row(line);
    std::vector<double> v(20);
    for (double& x : v) row >> x;
    ASSERT_FALSE(row.fail()) << line;
    EXPECT_DOUBLE_EQ(v[1], g.mass);
    for (int k = 5; k < 8; ++k) EXPECT_NEAR(v[k], g.inertia, 1e-9 * g.inertia);
    for (int k = 8; k < 11; ++k) EXPECT_NEAR(v[k], 0.0, 1e-9 * g.inertia);
    ++rows;
  }
  EXPECT_EQ(rows, 150);

  // hertz/material with nu = 0 and E = 2 E*, and the restitution whose LAMMPS Tsuji alpha is
  // tetrasand's damping strength.
  const PairCoefficients p = make_pair_coefficients(scene.materials[0], scene.materials[0], NormalDamping::Tsuji);
  const std::string in = read_file(deck.input);
  const std::size_t at = in.find("pair_coeff      1 1 hertz/material ");
  ASSERT_NE(at, std::string::npos) << in;
  std::istringstream coeff(in.substr(at + 35));
  double modulus = 0, restitution = 0, nu = -1;
  coeff >> modulus >> restitution >> nu;
  EXPECT_NEAR(modulus, 2 * p.effective_modulus, 1e-6 * modulus);
  EXPECT_EQ(nu, 0.0);
  EXPECT_NEAR(lammps_tsuji_alpha(restitution), p.damping_strength, 1e-9);
  EXPECT_NE(in.find("zplane 0 NULL"), std::string::npos);
  EXPECT_NE(in.find("xplane NULL 0.01"), std::string::npos);
}

// tetrasand's static-friction spring (k_t = 8 G* sqrt(R* delta)) becomes LAMMPS's mindlin with the same
// 8 G* (measured: the 150-grain bed then settles 1.1 % apart, 6.51 vs 6.58 mm).
TEST(ExportLammps, SpringFrictionBecomesMindlinWithTetrasandsStiffness) {
  const fs::path dir = test::temp_dir();
  Scene scene = bed_scene(dir);
  scene.simulation.step.tangential = TangentialModel::Spring;
  const LammpsDeck deck = export_lammps(scene, dir / "deck");
  const PairCoefficients p = make_pair_coefficients(scene.materials[0], scene.materials[0], NormalDamping::Tsuji);
  const std::string in = read_file(deck.input);
  const std::size_t at = in.find("tangential mindlin ");
  ASSERT_NE(at, std::string::npos) << in;
  EXPECT_EQ(in.find("linear_nohistory"), std::string::npos);
  const double k_t = std::stod(in.substr(at + 19));
  EXPECT_NEAR(k_t, 8 * p.effective_shear_modulus, 1e-9 * k_t);
}

TEST(ExportLammps, RefusesThesisDampingNamingTheScene) {
  const fs::path dir = test::temp_dir();
  Scene scene = bed_scene(dir);
  scene.simulation.step.normal_damping = NormalDamping::Thesis;
  try {
    export_lammps(scene, dir / "deck");
    FAIL() << "exported a scene with thesis damping";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.toml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("normal_damping"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "deck" / "in.tetrasand"));
}

// Every number the deck holds passes the value checker: a gravity whose norm overflows would write
// `inf` and `-nan` (a decks LAMMPS cannot read, of a scene `sim` refuses). Nothing is written.
TEST(ExportLammps, NonFiniteNumbersAreRefusedBeforeAnyFileIsWritten) {
  const fs::path dir = test::temp_dir();
  Scene scene = bed_scene(dir);
  scene.gravity = Eigen::Vector3d(0, 0, -1e200);
  try {
    export_lammps(scene, dir / "deck");
    FAIL() << "exported a deck with a non-finite number";
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("scene.toml: cannot export to LAMMPS: the deck would hold the non-finite"),
        std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "deck" / "in.tetrasand"));
  EXPECT_FALSE(fs::exists(dir / "deck" / "data.tetrasand"));
}

TEST(ExportLammps, CommandWritesDeckAndFailsOnBadScene) {
  const fs::path dir = test::temp_dir();
  bed_scene(dir);
  std::string out;
  EXPECT_EQ(test::run_tetrasand("export lammps '" + (dir / "scene.toml").string() + "' -o '" + (dir / "d").string() + "'",
                                &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(dir / "d" / "in.tetrasand")) << out;
  // --json: standard output is one object naming every file written, each there.
  ASSERT_EQ(test::run_tetrasand("export lammps '" + (dir / "scene.toml").string() + "' -o '" + (dir / "j").string() +
                                    "' --json 2>/dev/null | cat > '" + (dir / "deck.json").string() + "'"),
            0);
  std::ifstream json_in(dir / "deck.json");
  const nlohmann::json deck = nlohmann::json::parse(json_in, nullptr, false);
  ASSERT_FALSE(deck.is_discarded()) << "standard output is not one JSON object";
  EXPECT_GT(deck.at("dynamic_bodies").get<int>(), 0);
  ASSERT_FALSE(deck.at("files").empty());
  for (const auto& f : deck.at("files")) EXPECT_TRUE(fs::exists(f.get<std::string>())) << f;
  write_file_atomically(dir / "bad.toml", "[simulation]\nduration = -1\n");
  EXPECT_EQ(test::run_tetrasand("export lammps '" + (dir / "bad.toml").string() + "' -o '" + (dir / "e").string() + "'",
                                &out),
            1)
      << out;
  EXPECT_NE(out.find("bad.toml"), std::string::npos) << out;
}

// The headline check: LAMMPS running the exported deck settles the bed to the same mean grain
// height as tetrasand's CPU reference, within 4 % (measured: 0.9 % on 300 grains). A wrong mass,
// gravity, friction or wall would change the packing by more.
TEST(ExportLammps, LammpsSettlesExportedBedToTetrasandsHeight) {
  const fs::path dir = test::temp_dir();
  const Scene scene = bed_scene(dir);
  const LammpsDeck deck = export_lammps(scene, dir / "deck");
  run_lammps(deck);
  if (HasFatalFailure()) return;
  const std::vector<std::map<long, double>> frames = dump_heights(dir / "deck" / "final.dump");
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(frames[0].size(), 150u);
  double lammps = 0;
  for (const auto& [mol, z] : frames[0]) lammps += z / 150.0;

  World last;
  RunHooks hooks;
  hooks.on_output = [&](const World& world, const StepStats&, std::int64_t) { last = world; };
  run_scene(scene, dir / "tetrasand", hooks);
  const double tetrasand = mean_grain_height(last);
  const double initial = mean_grain_height(make_world(scene));
  EXPECT_LT(tetrasand, 0.5 * initial);  // it did fall and settle
  EXPECT_NEAR(lammps / tetrasand, 1.0, 0.04) << "LAMMPS " << lammps << " m, tetrasand " << tetrasand << " m";
}

// The first rebound of a spinless bounce: LAMMPS's apex matches tetrasand's within 2 % (measured:
// 0.01 %). Handing LAMMPS the scene's e = 0.6 as is (its Tsuji polynomial is not the Hertz
// oscillator's) rebounds 1.9 times as high. The scene uses the symplectic integrator: forward Euler
// gains energy in each contact and rebounds 7 % higher than LAMMPS's velocity Verlet at this dt.
TEST(ExportLammps, LammpsBouncesExportedGrainToTetrasandsHeight) {
  const fs::path dir = test::temp_dir();
  const Scene scene = bounce_scene(dir);
  const LammpsDeck deck = export_lammps(scene, dir / "deck");
  run_lammps(deck);
  if (HasFatalFailure()) return;
  auto apex_after_bounce = [](const std::vector<double>& z) {
    std::size_t low = 0;
    for (std::size_t i = 0; i < z.size(); ++i) {
      if (z[i] < z[low]) low = i;
      if (i > low + 2 && z[i] < z[i - 1] && z[low] < 1.5e-3) break;  // falling again after the bounce
    }
    double apex = 0;
    for (std::size_t i = low; i < z.size() && (i == low || z[i] >= z[i - 1]); ++i) apex = z[i];
    return apex;
  };
  std::vector<double> lammps_z;
  for (const auto& frame : dump_heights(dir / "deck" / "particles.dump")) lammps_z.push_back(frame.begin()->second);
  std::vector<double> tetrasand_z;
  RunHooks hooks;
  hooks.on_output = [&](const World& world, const StepStats&, std::int64_t) {
    tetrasand_z.push_back(mean_grain_height(world));
  };
  run_scene(scene, dir / "tetrasand", hooks);
  ASSERT_EQ(lammps_z.size(), tetrasand_z.size());
  const double drop = tetrasand_z.front() - 1e-3;
  const double lammps = apex_after_bounce(lammps_z) - 1e-3, tetrasand = apex_after_bounce(tetrasand_z) - 1e-3;
  EXPECT_GT(tetrasand, 0.1 * drop);
  EXPECT_LT(tetrasand, 0.9 * drop);
  EXPECT_NEAR(lammps / tetrasand, 1.0, 0.02) << "rebound above the floor: LAMMPS " << lammps << " m, tetrasand "
                                             << tetrasand << " m, drop " << drop << " m";
}

// A 1 kg cube of sampled particles (assets/bodies/cube) dropped tilted by 30 degrees onto a floor
// tips onto a face; a kinematic cube slides past. LAMMPS, with the prop's own atom type and
// explicit mass and inertia, leaves it where tetrasand does: resting height within 0.1 mm, sideways
// within 2 mm (measured: 0.0 mm and 0.9 mm; with the coefficients matched at a grain's mass instead
// the cube pivots on its edge and ends 43 mm off).
TEST(ExportLammps, LammpsRestsExportedPropWhereTetrasandDoes) {
  const fs::path dir = test::temp_dir();
  for (const char* f : {"cube.body.json", "cube.particles.ply"}) fs::copy_file(test::asset(std::string("bodies/") + f), dir / f);
  const Scene scene = write_scene(dir, R"(
gravity = [0.0, 0.0, -9.81]
[[material]]
name = "wood"
E = 1.0e6
nu = 0.3
restitution = 0.5
mu = 0.5
gamma_s = 0.1
density = 1000.0
[grain]
radius = 1.0e-3
material = "wood"
[[prop]]
body = "cube.body.json"
position = [0.0, 0.0, 0.08]
orientation = [0.9659258, 0.2588190, 0.0, 0.0]
motion = "dynamic"
material = "wood"
[[prop]]
body = "cube.body.json"
position = [0.3, 0.0, 0.06]
motion = "kinematic"
velocity = [0.1, 0.0, 0.0]
material = "wood"
[[boundary]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "wood"
[simulation]
duration = 0.3
dt = "auto"
[output]
every = 2000
csv = false
)");
  const LammpsDeck deck = export_lammps(scene, dir / "deck");
  EXPECT_EQ(deck.dynamic_bodies, 1u);
  EXPECT_NE(read_file(deck.input).find("move linear 0.10000000000000001 0 0"), std::string::npos);
  run_lammps(deck);
  if (HasFatalFailure()) return;
  const std::vector<std::map<long, double>> frames = dump_heights(dir / "deck" / "final.dump");
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(frames[0].size(), 1u);
  World last;
  RunHooks hooks;
  hooks.on_output = [&](const World& world, const StepStats&, std::int64_t) { last = world; };
  run_scene(scene, dir / "tetrasand", hooks);
  std::size_t cube = 0;
  while (last.bodies.motion[cube] != MotionType::Dynamic) ++cube;
  // The dump gives the mean of the cube's particles (0.2 mm off its mesh's centre of mass): compare
  // tetrasand's particle mean with it.
  const std::vector<Eigen::Vector3d> x = particle_positions(last);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  const std::uint32_t first = last.bodies.first_particle[cube], count = last.bodies.particle_count[cube];
  for (std::uint32_t i = first; i < first + count; ++i) mean += x[i] / count;
  EXPECT_NEAR(mean.z(), 0.05 + 0.0084, 0.002);  // flat on a face: half the edge plus a particle radius
  EXPECT_NEAR(frames[0].begin()->second, mean.z(), 1e-4);
  std::ifstream in(dir / "deck" / "final.dump");
  std::string line;
  for (int k = 0; k < 9; ++k) std::getline(in, line);
  double y = 0;
  int n = 0;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    double id, mol, type, px, py;
    row >> id >> mol >> type >> px >> py;
    y += py;
    ++n;
  }
  EXPECT_NEAR(y / n, mean.y(), 2e-3);
}

// ---- Grain types and sizes (issue 18).

struct Sphere {
  Eigen::Vector3d x;  // m
  double r;           // m
  long body;
};

// The atoms of the last frame of a LAMMPS custom dump "id mol type x y z radius".
std::vector<Sphere> dump_spheres(const fs::path& file) {
  std::ifstream in(file);
  std::vector<Sphere> spheres;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: NUMBER OF ATOMS", 0) != 0) continue;
    std::getline(in, line);
    const long n = std::stol(line);
    for (int k = 0; k < 5; ++k) std::getline(in, line);
    spheres.clear();
    for (long i = 0; i < n && std::getline(in, line); ++i) {
      std::istringstream row(line);
      long id = 0, mol = 0, type = 0;
      Sphere s{};
      row >> id >> mol >> type >> s.x.x() >> s.x.y() >> s.x.z() >> s.r;
      s.body = mol;
      spheres.push_back(s);
    }
  }
  return spheres;
}

std::vector<Sphere> grain_spheres(const World& w) {
  std::vector<Sphere> spheres;
  const std::vector<Eigen::Vector3d> x = particle_positions(w);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (w.bodies.motion[w.particles.body[i]] == MotionType::Dynamic)
      spheres.push_back({x[i], w.particles.radius[i], static_cast<long>(w.particles.body[i])});
  }
  return spheres;
}

// The bed's figures of docs/validation.md (section "Bidisperse bed against LAMMPS"): H, twice the
// volume-weighted mean grain-centre height (a grain's volume ~ its spheres' r^3), and phi, the solid
// fraction of the spheres' union on a 40^3 grid in 0.25 H < z < 0.75 H, |x|, |y| < half - inset.
struct Bed {
  double height = 0;   // m
  double packing = 0;  // solid fraction
};
Bed measure_bed(const std::vector<Sphere>& spheres, double half, double inset) {
  std::map<long, std::pair<Eigen::Vector3d, double>> grains;  // body -> (sum of centres, volume)
  std::map<long, int> count;
  for (const Sphere& s : spheres) {
    auto& g = grains.try_emplace(s.body, Eigen::Vector3d::Zero(), 0.0).first->second;
    g.first += s.x;
    g.second += s.r * s.r * s.r;
    ++count[s.body];
  }
  double moment = 0, volume = 0;
  for (const auto& [body, g] : grains) {
    moment += g.first.z() / count[body] * g.second;
    volume += g.second;
  }
  Bed bed;
  bed.height = 2 * moment / volume;
  const int n = 40;
  const double lo = -half + inset, span = 2 * (half - inset), z0 = 0.25 * bed.height,
               zspan = 0.5 * bed.height;
  int solid = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d p(lo + (i + 0.5) * span / n, lo + (j + 0.5) * span / n,
                                z0 + (k + 0.5) * zspan / n);
        solid += std::any_of(spheres.begin(), spheres.end(),
                             [&](const Sphere& s) { return (s.x - p).squaredNorm() < s.r * s.r; });
      }
  bed.packing = solid / static_cast<double>(n * n * n);
  return bed;
}

// The pre-set criterion of docs/validation.md: the bidisperse bed (100 fine r = 0.75 mm and 100 coarse
// r = 1.25 mm grains, one lattice, a smooth 2 cm box) settles in LAMMPS to tetrasand's bed height and
// packing fraction within 3 % each, from the same total grain mass.
TEST(ExportLammps, LammpsSettlesExportedBidisperseBedToTetrasandsHeightAndPacking) {
  const fs::path dir = test::temp_dir();
  Scene scene = write_scene(dir, read_file(test::asset("scenes/reference/bidisperse_bed.toml")));
  const World initial = make_world(scene);
  const LammpsDeck deck = export_lammps(scene, dir / "deck");
  EXPECT_EQ(deck.dynamic_bodies, 200u);
  run_lammps(deck);
  if (HasFatalFailure()) return;
  World last;
  RunHooks hooks;
  hooks.on_output = [&](const World& world, const StepStats&, std::int64_t) { last = world; };
  run_scene(scene, dir / "tetrasand", hooks);

  // The same grains: 400 spheres of each size, the same total mass in both decks.
  const std::vector<Sphere> lammps = dump_spheres(dir / "deck" / "final.dump"), ours = grain_spheres(last);
  ASSERT_EQ(lammps.size(), 800u);
  std::map<double, int> sizes;
  for (const Sphere& s : lammps) ++sizes[std::round(s.r * 1e6)];
  EXPECT_EQ(sizes, (std::map<double, int>{{750.0, 400}, {1250.0, 400}}));
  double mass = 0, rigid = 0;
  for (std::size_t b = 0; b < initial.bodies.size(); ++b) mass += 1 / initial.bodies.inverse_mass[b];
  std::istringstream bodies(read_file(dir / "deck" / "bodies.rigid"));
  std::string line;
  while (std::getline(bodies, line) && line[0] == '#') {
  }
  while (std::getline(bodies, line)) {
    std::istringstream row(line);
    double id = 0, m = 0;
    row >> id >> m;
    rigid += m;
  }
  EXPECT_NEAR(rigid / mass, 1.0, 1e-12);
  // Settled: less kinetic energy per grain than lifting a fine grain by a tenth of its radius.
  const double fine = make_tetrahedral_grain(0.75e-3, 1.5e-3, 2600).mass;
  const Energy e = energy(last);
  EXPECT_LT((e.translational + e.rotational) / 200, 0.1 * fine * 9.81 * 0.75e-3);

  const Bed a = measure_bed(lammps, 0.01, 2.5e-3), b = measure_bed(ours, 0.01, 2.5e-3);
  RecordProperty("H_lammps_mm", std::to_string(a.height * 1e3));
  RecordProperty("H_tetrasand_mm", std::to_string(b.height * 1e3));
  RecordProperty("phi_lammps", std::to_string(a.packing));
  RecordProperty("phi_tetrasand", std::to_string(b.packing));
  std::printf(
      "bidisperse bed: H LAMMPS %.4f mm, tetrasand %.4f mm (%+.2f %%); phi LAMMPS %.4f, tetrasand %.4f "
      "(%+.2f %%)\n",
      a.height * 1e3, b.height * 1e3, (a.height / b.height - 1) * 100, a.packing, b.packing,
      (a.packing / b.packing - 1) * 100);
  EXPECT_LT(b.height, 0.5 * 2 * 0.075);  // fell and settled (filled up to 15 cm)
  EXPECT_NEAR(a.height / b.height, 1.0, 0.03)
      << "bed height LAMMPS " << a.height << " m, tetrasand " << b.height;
  EXPECT_NEAR(a.packing / b.packing, 1.0, 0.03)
      << "packing LAMMPS " << a.packing << ", tetrasand " << b.packing;
}

// A pour of two types, one sieved into two sizes and the other continuous: one molecule template per
// type and size (sieve class, or size bin of the continuous one), fix deposit drawing them in the
// emitter's proportions; LAMMPS runs the deck and inserts grains of each size.
TEST(ExportLammps, PolydispersePourWritesOneTemplatePerTypeAndSizeAndRunsInLammps) {
  const fs::path dir = test::temp_dir();
  std::string text = read_file(test::asset("scenes/reference/bidisperse_bed.toml"));
  const std::string fill =
      text.substr(text.find("[[emitter]]"), text.find("[[boundary]]") - text.find("[[emitter]]"));
  text.replace(text.find(fill), fill.size(), R"([[emitter]]
type = "pour"
min = [-0.008, -0.008, 0.02]
max = [0.008, 0.008, 0.04]
count = 20
rate = 1000.0
grain = "fine"
size = { sieve = [[0.8, 0.5], [1.0, 0.5]] }
seed = 3
[[emitter]]
type = "pour"
min = [-0.008, -0.008, 0.05]
max = [0.008, 0.008, 0.07]
count = 20
rate = 1000.0
grain = "coarse"
size = { distribution = "uniform", min = 0.9, max = 1.1 }
seed = 4

)");
  text.replace(text.find("duration = 0.5"), 14, "duration = 0.03");
  const Scene scene = write_scene(dir, text);
  const LammpsDeck deck = export_lammps(scene, dir / "deck");
  const std::string in = read_file(deck.input);
  // 2 sieve classes + 5 size bins.
  EXPECT_NE(in.find("molecule        grain grain1.mol grain2.mol grain3.mol grain4.mol grain5.mol grain6.mol "
                    "grain7.mol\n"),
            std::string::npos)
      << in;
  for (int k = 1; k <= 7; ++k) EXPECT_TRUE(fs::exists(dir / "deck" / fmt::format("grain{}.mol", k))) << k;
  EXPECT_FALSE(fs::exists(dir / "deck" / "grain.mol"));
  EXPECT_NE(in.find("mol grain molfrac "), std::string::npos) << in;
  run_lammps(deck);
  if (HasFatalFailure()) return;
  std::set<double> radii;
  for (const Sphere& s : dump_spheres(dir / "deck" / "final.dump")) radii.insert(std::round(s.r * 1e7));
  EXPECT_GE(radii.size(), 4u) << "LAMMPS inserted grains of " << radii.size() << " sizes";
  EXPECT_TRUE(radii.count(6000.0) && radii.count(7500.0)) << "both sieve classes of the fine grain";
}

}  // namespace
}  // namespace ts::exporter

namespace ts::exporter {
namespace {

// A state handed on mid-flight: a spinning tetrahedral grain (a rigid body, its momenta in
// bodies.rigid) and a spinning free sphere (a plain LAMMPS sphere, its velocities in the data file)
// fly on in LAMMPS exactly as their state says: centres on the parabola x0 + v t + g t^2 / 2 (velocity
// Verlet is exact under constant gravity) and the grain's spheres turned by the constant spin of its
// isotropic inertia. A deck that dropped the velocities would leave both 47 mm short.
TEST(ExportLammps, StateDeckFliesRigidGrainsAndFreeSpheresOnWithTheirVelocitiesAndSpins) {
  const fs::path dir = test::temp_dir();
  const Scene scene = flight_scene(dir);
  World world = make_world(scene);
  ASSERT_EQ(world.bodies.size(), 1u);
  world.bodies.linear_velocity[0] = Eigen::Vector3d(0.3, -0.2, 0.8);
  world.bodies.angular_velocity[0] = Eigen::Vector3d(5.0, 0.0, 20.0);
  const double r = 1.5e-3, mass = 2600.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  BodyDesc sphere;
  sphere.position = Eigen::Vector3d(0.05, 0.0, 0.4);
  sphere.linear_velocity = Eigen::Vector3d(-0.5, 0.1, 1.5);
  sphere.angular_velocity = Eigen::Vector3d(0.0, 30.0, 0.0);
  sphere.inverse_mass = 1.0 / mass;
  sphere.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * mass * r * r);
  add_body(world, sphere, {Eigen::Vector3d::Zero()}, {r}, 0);
  const World start = world;

  LammpsStateRun run;
  run.duration = 0.05;
  run.dt = 1e-5;
  const LammpsDeck deck = export_lammps_state(scene, world, run, dir / "deck");
  const std::string in = read_file(deck.input);
  EXPECT_NE(in.find("fix             rb rigid rigid/small molecule infile bodies.rigid"), std::string::npos) << in;
  EXPECT_NE(in.find("fix             spheres spheres nve/sphere"), std::string::npos) << in;
  EXPECT_EQ(in.find("dump            particles"), std::string::npos) << "no per-step dump was asked for";
  run_lammps(deck);
  if (HasFatalFailure()) return;

  const auto atoms = dump_atoms(dir / "deck" / "final.dump");
  ASSERT_EQ(atoms.size(), 2u);
  const double t = static_cast<double>(deck.steps) * run.dt;
  EXPECT_NEAR(t, 0.05, 1e-12);
  auto flown = [&](std::size_t b) {
    return Eigen::Vector3d(start.bodies.position[b] + start.bodies.linear_velocity[b] * t + 0.5 * scene.gravity * t * t);
  };
  // Molecule 1: the grain (rigid bodies first), 2: the sphere.
  const std::vector<Eigen::Vector3d>& grain = atoms.at(1);
  ASSERT_EQ(grain.size(), 4u);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : grain) centre += x / 4.0;
  EXPECT_LT((centre - flown(0)).norm(), 1e-9) << centre.transpose() << " against " << flown(0).transpose();
  ASSERT_EQ(atoms.at(2).size(), 1u);
  EXPECT_LT((atoms.at(2)[0] - flown(1)).norm(), 1e-9) << atoms.at(2)[0].transpose() << " against " << flown(1).transpose();
  const Eigen::Vector3d omega = start.bodies.angular_velocity[0];
  const Eigen::Quaterniond turned =
      Eigen::Quaterniond(Eigen::AngleAxisd(omega.norm() * t, omega.normalized())) * start.bodies.orientation[0];
  const double grain_radius = start.particles.radius[0];
  for (std::uint32_t k = 0; k < 4; ++k) {
    const Eigen::Vector3d expected = flown(0) + turned * start.particles.offset[k];
    EXPECT_LT((grain[k] - expected).norm(), 1e-3 * grain_radius) << "sphere " << k << " of the grain";
  }
}

// A bed of spheres (each grain of the reference bed made one sphere of its volume and mass) that
// tetrasand has let fall for 0.25 s, handed to LAMMPS with a static body parked 1 km below left
// out: LAMMPS continues it for 0.05 s to the mean height tetrasand continues it to, within 2 % of a
// sphere's radius, so the state (overlaps, velocities) carries over without a jolt. A static body
// appended after the grains (as a silo's rim is) stays a wall: no grain becomes a "dynamic prop"
// with an atom type of its own.
TEST(ExportLammps, StateDeckContinuesATetrasandSphereBedWhereTetrasandDoes) {
  const fs::path dir = test::temp_dir();
  const Scene scene = bed_scene(dir);
  World world = make_world(scene);
  grains_to_spheres(world);
  BodyDesc parked;
  parked.position = Eigen::Vector3d(0, 0, -1e3);
  parked.motion = MotionType::Static;
  add_body(world, parked, {Eigen::Vector3d::Zero()}, {1e-3}, 0);
  BodyDesc post = parked;
  post.position = Eigen::Vector3d(0.5, 0.5, 0.0);  // far from the box's grains, kept
  add_body(world, post, {Eigen::Vector3d::Zero()}, {1e-3}, 0);
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, world, nullptr);
  CpuStepper stepper(world, settings);
  const auto steps = [&](double seconds) { return static_cast<std::int64_t>(std::ceil(seconds / settings.dt - 1e-9)); };
  for (std::int64_t s = 0; s < steps(0.25); ++s) stepper.step(world);

  const std::vector<Eigen::Vector3d> x = particle_positions(world);
  const World handed = without_particles(world, [&](std::size_t i) { return x[i].z() > -100.0; });
  EXPECT_EQ(handed.bodies.size(), world.bodies.size() - 1) << "the parked body is left out";
  LammpsStateRun run;
  run.duration = 0.05;
  run.dt = settings.dt;
  const LammpsDeck deck = export_lammps_state(scene, handed, run, dir / "deck");
  EXPECT_NE(read_file(dir / "deck" / "data.tetrasand").find("\n1 atom types\n"), std::string::npos);
  EXPECT_EQ(read_file(deck.input).find("dynamic prop"), std::string::npos) << read_file(deck.input);
  run_lammps(deck);
  if (HasFatalFailure()) return;
  const auto frames = dump_heights(dir / "deck" / "final.dump");
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(frames[0].size(), 150u);
  double lammps = 0;
  for (const auto& [mol, z] : frames[0]) lammps += z / 150.0;

  for (std::int64_t s = 0; s < deck.steps; ++s) stepper.step(world);
  const double tetrasand = mean_grain_height(world);
  const double radius = std::cbrt(4.0) * scene.grains.at(0).radius;
  std::fprintf(stderr, "mean height after 0.30 s: LAMMPS %.6e m, tetrasand %.6e m, gap %.3g r\n", lammps, tetrasand,
               std::abs(lammps - tetrasand) / radius);
  EXPECT_NEAR(lammps, tetrasand, 0.02 * radius) << "mean height after 0.30 s: LAMMPS " << lammps << " m, tetrasand "
                                                << tetrasand << " m";
}

}  // namespace
}  // namespace ts::exporter
