// The runs behind docs/validation.md, through the library (CPU reference; the agreement run also on
// the GPU pipeline), written as CSV files that bench/validation/report.py plots and compares with
// the literature. Usage:
//   tetrasand_validation_runs OUT_DIR [restitution|repose|silo
//   [SCENE]|silo-spheres|silo[-spheres]-lammps|forces-backed|forces-gentle [BATCHES]|column [R0_M,R0_M,...]|all|
//   agreement[-heap|-silo|-bed]|
//                                      oedometer[-tetrahedra|-spheres] [SCENE]|
//   mixed[-heap|-silo] [double|full-double] [SILO_SEEDS] [HEAP_SEEDS]]
// `all` is the physical report: restitution and repose take minutes, the column collapse (8 x 20,000
// grains) and the Mankoc-sized silo (80,000 grains) tens of minutes each on two cores. `agreement`
// (GPU pipeline against the CPU reference) is separate: on llvmpipe it is the slow part. `mixed` runs
// the agreement's heap and silo on the GPU pipeline in one fp64 precision (mixed or full double).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/bench_scenes.h"
#include "core/atomic_file.h"
#include "gpu/context.h"
#include "sim/cpu_stepper.h"
#include "export/lammps_deck.h"
#include "sim/gpu_stepper.h"
#include "scene/scene.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "sim/time_step.h"

namespace {

namespace fs = std::filesystem;
using namespace ts::sim;
using namespace ts::scene;
using namespace ts::exporter;

// One solid sphere (r = 1 mm, quartz, E = 10 MPa) hitting a smooth wall of the same material head on
// at `speed`, no gravity: the rebound speed over the impact speed.
double sphere_restitution(double speed, NormalDamping damping) {
  Material sand;
  sand.restitution = 0.65;
  const double r = 1e-3;                                                     // m
  const double m = sand.density * 4.0 / 3.0 * std::numbers::pi * r * r * r;  // kg
  World world;
  world.materials = {sand};
  world.gravity = Eigen::Vector3d::Zero();
  world.walls.planes.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0});
  BodyDesc body;
  body.position = Eigen::Vector3d(0, 0, r * 1.001);
  body.linear_velocity = Eigen::Vector3d(0, 0, -speed);
  body.inverse_mass = 1 / m;
  body.inverse_inertia = Eigen::Matrix3d::Identity() / (0.4 * m * r * r);
  add_body(world, body, {Eigen::Vector3d::Zero()}, {r}, 0);
  const PairCoefficients p = make_pair_coefficients(sand, sand, damping);
  StepSettings settings;
  settings.normal_damping = damping;
  settings.integrator = Integrator::SemiImplicitEuler;
  settings.dt = hertz_contact_duration(m, r, p.effective_modulus, speed) / 200;  // s
  settings.cfl = 0;
  settings.check_energy = false;
  CpuStepper stepper(world, settings);
  for (int i = 0; i < 100000; ++i) {
    stepper.step(world);
    if (world.bodies.position[0].z() > r * 1.001 && world.bodies.linear_velocity[0].z() > 0) break;
  }
  return world.bodies.linear_velocity[0].z() / speed;
}

void restitution(const fs::path& out) {
  std::string csv = "impact_speed_m_s,e_tsuji,e_thesis\n";
  for (double v : {0.03, 0.1, 0.3, 1.0, 3.0, 10.0}) {
    csv += fmt::format("{},{:.6f},{:.6f}\n", v, sphere_restitution(v, NormalDamping::Tsuji),
                       sphere_restitution(v, NormalDamping::Thesis));
  }
  ts::write_file_atomically(out / "restitution.csv", csv);
}

// A scene of assets/scenes/reference/, shared with the peers bench and the tests.
Scene reference(const std::string& name) { return load_scene(ts::bench::reference_scene(name)); }

void set_friction(Scene& scene, double mu) {
  for (Material& m : scene.materials) m.friction = mu;
}

struct Run {
  World last;
  std::vector<std::pair<double, std::vector<double>>> heights;  // (time, grain centre heights)
  double seconds = 0;
  std::int64_t steps = 0;
  std::size_t grains = 0;
};

using MakeStepper = StepperFactory;

// Runs `scene` (on the CPU reference unless `make` says otherwise) with no files but the runner's own.
// `edit`, when given, changes the initial world (RunHooks::edit_initial_world).
Run run(Scene scene, const fs::path& dir, const std::string& name, bool record_heights,
        const MakeStepper& make = {}, const std::function<void(World&)>& edit = {}) {
  fs::create_directories(dir);
  scene.output.csv = false;
  scene.output.ply = false;
  Run r;
  RunHooks hooks;
  hooks.edit_initial_world = edit;
  hooks.on_output = [&](const World& world, const StepStats&, std::int64_t) {
    r.last = world;
    if (!record_heights) return;
    std::vector<double> z;
    for (std::size_t b = 0; b < world.bodies.size(); ++b) {
      if (world.bodies.motion[b] == MotionType::Dynamic) z.push_back(world.bodies.position[b].z());
    }
    r.heights.emplace_back(world.time, std::move(z));
  };
  const auto start = std::chrono::steady_clock::now();
  const RunResult result = run_scene(scene, dir / name, hooks, make);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.steps = result.steps;
  r.grains = result.grains;
  std::fprintf(stderr, "%s: %zu grains, %lld steps, %.1f s\n", name.c_str(), r.grains,
               static_cast<long long>(r.steps), r.seconds);
  return r;
}

// 3,000 coarse grains (r = 5 mm) poured at 1,000 grains/s from a box 5-30 cm above a rough floor with
// no side walls pile up into a heap (reference/coarse_pile.toml, scaled up from its 300 grains); its
// surface slope is the angle of repose.
void repose(const fs::path& out) {
  std::string csv = "mu,grains,seconds\n";
  for (double mu : {0.1, 0.3, 0.5, 0.8}) {
    Scene scene = reference("coarse_pile.toml");
    set_friction(scene, mu);
    scene.emitters.at(0).count = 3000;
    scene.emitters.at(0).rate = 1000;
    // A 16 cm x 16 cm box 5-30 cm up: 360 release sites, enough to keep up with 1,000 grains/s.
    scene.emitters.at(0).min = Eigen::Vector3d(-0.08, -0.08, 0.05);
    scene.emitters.at(0).max = Eigen::Vector3d(0.08, 0.08, 0.30);
    scene.boundaries.at(0).size = Eigen::Vector2d(0.8, 0.8);  // the heap spreads to ~0.25 m
    scene.simulation.duration = 4.0;                          // s: a 3 s pour, then 1 s at rest
    scene.simulation.step.integrator = Integrator::SemiImplicitEuler;
    const Run r = run(scene, out / "runs", fmt::format("repose_mu{}", mu), false);
    ts::write_file_atomically(out / fmt::format("heap_mu{}.csv", mu), ts::bench::grain_centres_csv(r.last));
    csv += fmt::format("{},{},{:.1f}\n", mu, r.grains, r.seconds);
  }
  ts::write_file_atomically(out / "repose.csv", csv);
}

// The silo of reference/silo.toml with an orifice of diameter `d` (m).
Scene silo_scene(double d) {
  Scene scene = reference("silo.toml");
  scene.boundaries.at(1).hole_radius = d / 2;
  return scene;
}

// Rows "label,time,discharged": grains more than 2 mm below the plate at each output.
std::string discharge_rows(const std::string& label, const Run& r) {
  std::string rows;
  for (const auto& [t, z] : r.heights) {
    rows += fmt::format("{},{:.5f},{}\n", label, t, std::count_if(z.begin(), z.end(), [](double h) { return h < -2e-3; }));
  }
  return rows;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// The 99th percentile of the dynamic grains' speeds (m/s): "at rest" ignores a few rattlers.
double speed_p99(const World& world) {
  std::vector<double> v;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] == MotionType::Dynamic) v.push_back(world.bodies.linear_velocity[b].norm());
  }
  return v.empty() ? 0.0 : percentile(v, 0.99);
}

// Preparation only (filling a silo or a column, never a measured phase): from `from_time` on, every
// dynamic body's velocities decay as exp(-t / time_constant) on top of the contact forces, like
// Yade's global damping, so a fill that landed as a block stops rebounding in a few time constants.
// It removes only motion, yet it changes the path to rest and so can change the packing reached
// (the silo's base contact forces did change with it; docs/validation.md).
struct SettleDamping {
  double from_time = 1e300;      // s after the phase starts
  double time_constant = 0.05;   // s
};

void damp_velocities(World& world, double factor) {
  Bodies& b = world.bodies;
  for (std::size_t k = 0; k < b.size(); ++k) {
    if (b.motion[k] != MotionType::Dynamic) continue;
    b.linear_velocity[k] *= factor;
    b.angular_velocity[k] *= factor;
  }
}

// m: the height of the highest dynamic body's centre, where a falling lattice starts from.
double lattice_top(const World& world) {
  double top = 0;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] == MotionType::Dynamic) top = std::max(top, world.bodies.position[b].z());
  }
  return top;
}

// Damping for a lattice that falls from its top onto the floor: from the moment its top grain
// would land in free fall.
SettleDamping damping_after_fall(const Scene& scene, const World& world) {
  SettleDamping damping;
  damping.from_time = std::sqrt(2 * lattice_top(world) / scene.gravity.norm());
  return damping;
}

// Steps until the grains are at rest or what is measured of them has stopped changing, after at
// least `min_time` and at most `max_time` of simulated time. Every 10 ms it checks whether 99 % of
// the grains move slower than `rest_speed`, or whether they move slower than 10 x `rest_speed` and
// `measure` (a height or a radius, m) stayed within 0.3 % over the last 0.1 s (a deposit's creeping
// edge keeps a few grains moving long after its extent has settled; a fill still bouncing after its
// fall fails both). Returns the simulated time it ran. Progress goes to stderr: minutes each.
double run_until_rest(CpuStepper& stepper, World& world, double min_time, double max_time, double rest_speed,
                      const std::string& label, const std::function<double()>& measure,
                      const SettleDamping& damping = {}) {
  const double dt = stepper.settings().dt, t0 = world.time;
  const auto check_every = std::max<std::int64_t>(1, std::llround(1e-2 / dt));
  const auto wall = std::chrono::steady_clock::now();
  const double damping_factor = std::exp(-dt / damping.time_constant);
  std::vector<double> history;  // `measure` at each check
  for (std::int64_t s = 1;; ++s) {
    stepper.step(world);
    const double t = world.time - t0;
    if (t >= damping.from_time) damp_velocities(world, damping_factor);
    if (s % check_every != 0) continue;
    const double speed = speed_p99(world);
    history.push_back(measure());
    bool settled = false;
    if (history.size() > 10 && speed < 10 * rest_speed) {
      const auto window = std::minmax_element(history.end() - 11, history.end());
      settled = *window.second - *window.first < 3e-3 * std::abs(history.back());
    }
    if (history.size() % 10 == 0) {
      std::fprintf(stderr, "  %s: t = %.2f s, 99 %% of grains below %.3f m/s, extent %.4f m, %.0f s wall\n",
                   label.c_str(), t, speed, history.back(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count());
    }
    if ((t >= min_time && (speed < rest_speed || settled)) || t >= max_time) return t;
  }
}

// A CPU stepper for a scene whose lattice falls from its top: dt bounded at that impact speed.
CpuStepper tall_scene_stepper(Scene& scene, const World& world) {
  scene.simulation.max_impact_speed = std::sqrt(2 * scene.gravity.norm() * lattice_top(world));
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, world, nullptr);
  settings.check_energy = false;  // the runs take grains out (silo) or remove a wall (column)
  return CpuStepper(world, settings);
}

// The normal contact forces of a state at rest, one row per contact between particles of different
// bodies (smooth walls left out): "normal_force_N,z_m,r_m,base,grain,fz_N", z and r the contact
// point's height and distance from the axis, base = 1 where the partner is a static particle (the
// rough floor), grain the body of the grain's particle and fz_N the force's vertical part on it (summed
// per grain at the base, the load each grain puts on the floor, as Mueth et al.'s carbon paper sees it).
void write_contact_forces(const World& world, const StepSettings& settings, const fs::path& file) {
  CpuStepper stepper(world, settings);
  const std::vector<Eigen::Vector3d> x = particle_positions(world);
  std::string csv = "normal_force_N,z_m,r_m,base,grain,fz_N\n";
  for (const ContactRecord& c : stepper.contacts(world)) {  // c.particle is a grain's (dynamic) particle
    if (c.partner < 0) continue;
    const auto j = static_cast<std::size_t>(c.partner);
    const Eigen::Vector3d normal = (x[c.particle] - x[j]).normalized();
    const bool base = world.bodies.motion[world.particles.body[j]] == MotionType::Static;
    csv += fmt::format("{:.6e},{:.5f},{:.5f},{},{},{:.6e}\n", std::abs(c.force.dot(normal)), c.point.z(),
                       c.point.head<2>().norm(), base ? 1 : 0, world.particles.body[c.particle], c.force.z());
  }
  ts::write_file_atomically(file, csv);
}

// m: a fill's height, the 95th percentile of its grains' centre heights (0 without grains).
double fill_height_of(const World& world) {
  std::vector<double> tops;
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    if (world.bodies.motion[b] == MotionType::Dynamic) tops.push_back(world.bodies.position[b].z());
  }
  return tops.empty() ? 0.0 : percentile(tops, 0.95);
}

// A silo scene's fill (its first emitter) dropped as a lattice and settled on the closed plate,
// damped once the lattice has landed; its contact forces go to `forces_file`.
struct SettledFill {
  World world;
  StepSettings settings;
  std::size_t grains = 0;
  double settle_time = 0, fill = 0, wall_seconds = 0;  // s simulated, m (95th percentile of centre heights), s wall
};

// `reshape`, when given, changes the initial world before it falls (grains_to_spheres).
SettledFill settle_fill(Scene& scene, const std::string& label, const fs::path& forces_file,
                        const std::function<void(World&)>& reshape = {}) {
  SettledFill f;
  f.world = make_world(scene);
  if (reshape) reshape(f.world);
  CpuStepper settle = tall_scene_stepper(scene, f.world);
  const SettleDamping damping = damping_after_fall(scene, f.world);
  f.settings = settle.settings();
  f.grains = scene.emitters.at(0).count;
  std::fprintf(stderr, "%s: %zu grains, dt = %.3g s, settling\n", label.c_str(), f.grains, f.settings.dt);
  const auto wall = std::chrono::steady_clock::now();
  auto fill_height = [&] { return fill_height_of(f.world); };
  f.settle_time = run_until_rest(settle, f.world, damping.from_time + 0.2, scene.simulation.duration, 0.02,
                                 label + " settle", fill_height, damping);
  f.fill = fill_height();
  f.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
  // A settled fill is a sand pile at rest in a cylinder, where the thesis (table 7.1) and Mueth et
  // al. 1998 measure the normal contact-force distribution.
  write_contact_forces(f.world, f.settings, forces_file);
  return f;
}

// Grains leave a silo's simulation as static bodies 10 cm apart on a square 1 km down, so they touch
// nothing and share no cell.
struct Parking {
  std::size_t slots = 0;
  void park(World& world, std::size_t k) {
    Bodies& b = world.bodies;
    b.motion[k] = MotionType::Static;
    b.inverse_mass[k] = 0;
    b.inverse_inertia[k].setZero();
    b.linear_velocity[k].setZero();
    b.angular_velocity[k].setZero();
    b.position[k] = Eigen::Vector3d(0.1 * static_cast<double>(slots % 200), 0.1 * static_cast<double>(slots / 200), -1e3);
    ++slots;
  }
};

struct OpenedOrifice {
  std::size_t rim_spheres = 0, removed_on_rim = 0;
};

// Opens an orifice of diameter `orifice` (m) in a settled silo's plate (the scene's second
// boundary): the plate's particles reaching into it move 1 km below, keeping x and y, and a round
// rim of the plate's spheres lines the hole, so its opening is a disc of D, not the ragged lattice
// edge (whose open area is that of a disc up to 0.9 d wider). A grain sphere resting in a lattice
// hollow reaches below the plate's tops, where a rim sphere can now stand: such grains would start
// deep in contact, so they are parked before the run starts.
OpenedOrifice open_orifice(World& world, const Scene& scene, double orifice, Parking& parking) {
  const Particles& p = world.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (world.bodies.motion[p.body[i]] != MotionType::Static) continue;
    if (p.offset[i].head<2>().norm() < orifice / 2 + p.radius[i]) world.particles.offset[i].z() -= 1e3;
  }
  const Boundary& plate = scene.boundaries.at(1);
  BodyDesc rim;
  rim.position = plate.point;
  rim.motion = MotionType::Static;
  const auto rim_offsets = round_hole_rim(Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(),
                                          orifice / 2, plate.particle_radius);
  add_body(world, rim, rim_offsets, std::vector<double>(rim_offsets.size(), plate.particle_radius), plate.material);
  std::vector<std::size_t> overlapping;
  const auto positions = particle_positions(world);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (world.bodies.motion[p.body[i]] != MotionType::Dynamic) continue;
    for (const Eigen::Vector3d& o : rim_offsets) {
      if ((positions[i] - plate.point - o).norm() < p.radius[i] + plate.particle_radius) {
        overlapping.push_back(p.body[i]);
        break;
      }
    }
  }
  std::sort(overlapping.begin(), overlapping.end());
  overlapping.erase(std::unique(overlapping.begin(), overlapping.end()), overlapping.end());
  for (std::size_t k : overlapping) parking.park(world, k);
  return {rim_offsets.size(), overlapping.size()};
}

// A large flat-bottomed silo within the size conditions of Mankoc et al. 2007
// (reference/silo_mankoc.toml, or `scene_file`): filled and settled once on a closed rough plate,
// damped once the lattice has landed (it falls ~4 m as one block, and the soft fill otherwise
// rebounds for seconds); then, for each orifice diameter (5, 6, 7 and 8 d), a copy of the settled
// silo has the plate's particles within D/2 of the axis taken away, a round rim lining the hole
// (round_hole_rim), and discharges undamped for 0.35 s. The settled fill's contact forces are written
// too. Discharged grains (5 cm below the plate) are parked far below as static bodies, so they cost
// nothing and pile up nowhere. `spheres`: each grain replaced by one sphere of its volume and mass
// before the fill falls (grains_to_spheres; the Beverloo reference silo of
// bench/validation/silo_spheres_criteria.md), so d is then the spheres' diameter.
constexpr double kDischargeTime = 0.35;  // s after a silo's orifice opens; the rate is fitted from 0.1 s

// The silo's fill settled on its closed plate (grains or, with `spheres`, spheres), its contact
// forces and silo_fill.csv written into `out`.
SettledFill settled_silo(const fs::path& out, Scene& scene, bool spheres) {
  SettledFill filled = settle_fill(scene, spheres ? "sphere silo" : "silo", out / "contact_forces.csv",
                                   spheres ? std::function<void(World&)>(grains_to_spheres)
                                           : std::function<void(World&)>());
  ts::write_file_atomically(out / "silo_fill.csv",
                            fmt::format("grains,settle_s,fill_m,width_m,dt_s,settle_wall_s\n{},{:.3f},{:.4f},{:.4f},{:.4g},{:.0f}\n",
                                        filled.grains, filled.settle_time, filled.fill,
                                        2 * scene.boundaries.at(0).radius, filled.settings.dt, filled.wall_seconds));
  return filled;
}

void silo(const fs::path& out, const fs::path& scene_file, bool spheres = false) {
  Scene scene = scene_file.empty() ? reference("silo_mankoc.toml") : load_scene(scene_file);
  const SettledFill filled = settled_silo(out, scene, spheres);
  const World& settled = filled.world;
  const double dt = filled.settings.dt;
  const std::size_t grains = filled.grains;
  const double d = 2 * scene.grains.at(0).radius * std::cbrt(4.0);  // m, volume-equivalent diameter
  std::string csv = "orifice_m,time_s,discharged\n";
  std::string runs = "orifice_m,grains,rim_spheres,removed_on_rim,seconds\n";
  for (double ratio : {5.0, 6.0, 7.0, 8.0}) {
    const double orifice = ratio * d;
    World world = settled;
    world.time = 0;
    Parking parking;
    const OpenedOrifice opened = open_orifice(world, scene, orifice, parking);
    auto park = [&](std::size_t k) { parking.park(world, k); };
    CpuStepper stepper(world, filled.settings);
    std::size_t parked = 0;
    const auto start = std::chrono::steady_clock::now();
    const auto steps = static_cast<std::int64_t>(std::ceil(kDischargeTime / dt));
    const auto every = std::max<std::int64_t>(1, std::llround(2e-3 / dt));
    for (std::int64_t s = 1; s <= steps; ++s) {
      stepper.step(world);
      if (s % every != 0) continue;
      for (std::size_t k = 0; k < world.bodies.size(); ++k) {
        if (world.bodies.motion[k] != MotionType::Dynamic || world.bodies.position[k].z() > -0.05) continue;
        park(k);
        ++parked;
      }
      csv += fmt::format("{:.5f},{:.5f},{}\n", orifice, world.time, parked);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "silo D = %.1f mm (%.2f d): %zu grains out in %.2f s (%zu on the rim removed first), %.0f s wall\n",
                 orifice * 1e3, ratio, parked, kDischargeTime, opened.removed_on_rim, seconds);
    runs += fmt::format("{:.5f},{},{},{},{:.1f}\n", orifice, grains, opened.rim_spheres, opened.removed_on_rim, seconds);
    ts::write_file_atomically(out / "silo.csv", csv);  // after each orifice: a stopped run keeps its rows
    ts::write_file_atomically(out / "silo_runs.csv", runs);
  }
}

// The silo's discharges handed to LAMMPS (bench/validation/silo_lammps_criteria.md): the fill settled
// by tetrasand as `silo` settles it, each orifice opened as `silo` opens it (widest first, so a
// partial run keeps the lever arm), and that state written as a LAMMPS deck into OUT/lammps_D<ratio>d
// (export_lammps_state, run 0.35 s at tetrasand's dt; the parked grains and plate particles left
// out). The deck logs the dynamic mass below z = -0.05 m every 2 ms as v_discharged (kg);
// bench/validation/silo_lammps.py runs LAMMPS on each and fits the rates.
void silo_lammps(const fs::path& out, bool spheres) {
  Scene scene = reference("silo_mankoc.toml");
  const SettledFill filled = settled_silo(out, scene, spheres);
  const double d = 2 * scene.grains.at(0).radius * std::cbrt(4.0);  // m, volume-equivalent diameter
  std::string decks = "orifice_m,ratio,deck,grains,rim_spheres,removed_on_rim,steps,dt_s\n";
  for (double ratio : {8.0, 5.0, 7.0, 6.0}) {
    const double orifice = ratio * d;
    World world = filled.world;
    world.time = 0;
    Parking parking;
    const OpenedOrifice opened = open_orifice(world, scene, orifice, parking);
    const std::vector<Eigen::Vector3d> x = particle_positions(world);
    const World handed = without_particles(world, [&](std::size_t i) { return x[i].z() > -100.0; });
    LammpsStateRun run;
    run.duration = kDischargeTime;
    run.dt = filled.settings.dt;
    run.thermo_every = std::max<std::int64_t>(1, std::llround(2e-3 / run.dt));
    run.before_run = {
        "region          below block INF INF INF INF INF -0.05 units box",
        "variable        discharged equal mass(dynamic,below)",
        "thermo_style    custom step time atoms v_discharged",
    };
    const std::string name = fmt::format("lammps_D{:.0f}d", ratio);
    const LammpsDeck deck = export_lammps_state(scene, handed, run, out / name);
    std::size_t grains = 0;
    for (std::size_t b = 0; b < handed.bodies.size(); ++b) grains += handed.bodies.motion[b] == MotionType::Dynamic;
    std::fprintf(stderr, "silo D = %.1f mm (%.0f d): LAMMPS deck %s, %zu grains, %zu on the rim removed, %lld steps\n",
                 orifice * 1e3, ratio, name.c_str(), grains, opened.removed_on_rim, static_cast<long long>(deck.steps));
    decks += fmt::format("{:.5f},{:.0f},{},{},{},{},{},{:.6g}\n", orifice, ratio, name, grains, opened.rim_spheres,
                         opened.removed_on_rim, deck.steps, run.dt);
    ts::write_file_atomically(out / "silo_lammps_decks.csv", decks);
  }
}

// More piles at rest for the contact-force distribution, whose base tail one fill does not settle:
// the silo's cylinder filled with `grains` per seed (seeds 1, 2, 3: other lattice jitters and
// orientations), each settled as the silo's fill is. One contact_forces_seedN.csv per seed and a
// forces_fills.csv of the fills.
void forces(const fs::path& out, std::size_t grains) {
  std::string fills = "seed,grains,settle_s,fill_m,settle_wall_s\n";
  for (std::uint64_t seed : {1, 2, 3}) {
    Scene scene = reference("silo_mankoc.toml");
    scene.emitters.at(0).count = grains;
    scene.emitters.at(0).seed = seed;
    const SettledFill f = settle_fill(scene, fmt::format("pile seed {}", seed), out / fmt::format("contact_forces_seed{}.csv", seed));
    fills += fmt::format("{},{},{:.3f},{:.4f},{:.0f}\n", seed, f.grains, f.settle_time, f.fill, f.wall_seconds);
    ts::write_file_atomically(out / "forces_fills.csv", fills);  // after each seed: a stopped run keeps its rows
  }
}

// The silo's own fill (80,000 grains, seed 17) settled as the silo's is, on the same rough plate backed
// by a smooth plane at its spheres' centres, so no grain sphere can sink into a gap of the plate's
// lattice (bench/validation/forces_backed_criteria.md): contact_forces.csv and silo_fill.csv, as the
// silo run writes them.
void forces_backed(const fs::path& out) {
  Scene scene = reference("silo_mankoc.toml");
  const Boundary& plate = scene.boundaries.at(1);
  Boundary backing;
  backing.type = BoundaryType::Plane;
  backing.normal = plate.normal;
  backing.point = plate.point - plate.normal * plate.particle_radius;  // the plate's sphere centres
  backing.material = plate.material;
  scene.boundaries.push_back(backing);
  const SettledFill f = settle_fill(scene, "backed silo fill", out / "contact_forces.csv");
  ts::write_file_atomically(out / "silo_fill.csv",
                            fmt::format("grains,settle_s,fill_m,settle_wall_s\n{},{:.3f},{:.4f},{:.0f}\n", f.grains,
                                        f.settle_time, f.fill, f.wall_seconds));
}

// A grain taken out of a world, to be put back later at another height.
struct HeldGrain {
  BodyDesc body;
  std::vector<Eigen::Vector3d> offsets;
  std::vector<double> radii;
  std::uint16_t material = 0;
  double bound = 0;  // m, bounding radius
};

// Takes the grains (bodies from `first_grain` on, which only emitters append) out of `world`, in
// the order of their height; the bodies before them stay.
std::vector<HeldGrain> take_grains(World& world, std::size_t first_grain) {
  const Bodies& b = world.bodies;
  const Particles& p = world.particles;
  std::vector<HeldGrain> held;
  for (std::size_t k = first_grain; k < b.size(); ++k) {
    HeldGrain g;
    g.body.position = b.position[k];
    g.body.orientation = b.orientation[k];
    g.body.inverse_mass = b.inverse_mass[k];
    g.body.inverse_inertia = b.inverse_inertia[k];
    g.bound = b.bounding_radius[k];
    for (std::uint32_t i = b.first_particle[k]; i < b.first_particle[k] + b.particle_count[k]; ++i) {
      g.offsets.push_back(p.offset[i]);
      g.radii.push_back(p.radius[i]);
    }
    g.material = p.material[b.first_particle[k]];
    held.push_back(std::move(g));
  }
  std::stable_sort(held.begin(), held.end(),
                   [](const HeldGrain& a, const HeldGrain& c) { return a.body.position.z() < c.body.position.z(); });
  const std::vector<std::uint32_t> owner = p.body;
  world = without_particles(world, [&](std::size_t i) { return owner[i] < first_grain; });
  return held;
}

// The silo's own fill (80,000 grains, seed 17, on the unbacked plate) released gently
// (bench/validation/forces_gentle_criteria.md): its lattice cut in height order into `batches`,
// each moved down to start one bounding radius above the pile's top and released once the pile
// before it has settled, damped from when its top grain would land, with the single lattice's time
// step. contact_forces.csv and silo_fill.csv, as the silo run writes them, and gentle_batches.csv.
void forces_gentle(const fs::path& out, std::size_t batches) {
  Scene scene = reference("silo_mankoc.toml");
  World world = make_world(scene);
  CpuStepper stepper = tall_scene_stepper(scene, world);  // dt for the 4 m fall: the same step as the silo's fill
  const std::vector<HeldGrain> held = take_grains(world, fixture_bodies(scene, world));
  const double g = scene.gravity.norm();
  auto fill_height = [&] { return fill_height_of(world); };
  std::fprintf(stderr, "gentle silo fill: %zu grains in %zu batches, dt = %.3g s\n", held.size(), batches,
               stepper.settings().dt);
  const auto wall = std::chrono::steady_clock::now();
  std::string csv = "batch,grains,drop_m,impact_speed_m_s,settle_s,fill_m,wall_s\n";
  double settle_time = 0;
  for (std::size_t k = 0; k < batches; ++k) {
    const std::size_t from = held.size() * k / batches, to = held.size() * (k + 1) / batches;
    double pile_top = 0;  // m: the plate's sphere tops are at z = 0
    for (std::size_t b = 0; b < world.bodies.size(); ++b) {
      if (world.bodies.motion[b] != MotionType::Dynamic) continue;
      pile_top = std::max(pile_top, world.bodies.position[b].z() + world.bodies.bounding_radius[b]);
    }
    double lowest = 1e300, highest = -1e300;
    for (std::size_t i = from; i < to; ++i) {
      lowest = std::min(lowest, held[i].body.position.z() - held[i].bound);
      highest = std::max(highest, held[i].body.position.z() + held[i].bound);
    }
    const double shift = std::min(0.0, pile_top + held[from].bound - lowest);  // never up
    for (std::size_t i = from; i < to; ++i) {
      BodyDesc body = held[i].body;
      body.position.z() += shift;
      add_body(world, body, held[i].offsets, held[i].radii, held[i].material);
    }
    stepper.reset_energy_reference(world);
    const double drop = std::max(0.0, highest + shift - pile_top);  // m: the batch's highest grain to the pile's top
    SettleDamping damping;
    damping.from_time = std::sqrt(2 * drop / g);
    const std::string label = fmt::format("gentle fill batch {}/{}", k + 1, batches);
    settle_time += run_until_rest(stepper, world, damping.from_time + 0.2, scene.simulation.duration, 0.02, label,
                                  fill_height, damping);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
    std::fprintf(stderr, "%s: %zu grains dropped up to %.3f m (%.2f m/s), fill %.4f m, %.0f s wall\n", label.c_str(),
                 to - from, drop, std::sqrt(2 * g * drop), fill_height(), seconds);
    csv += fmt::format("{},{},{:.4f},{:.3f},{:.3f},{:.4f},{:.0f}\n", k + 1, to - from, drop, std::sqrt(2 * g * drop),
                       settle_time, fill_height(), seconds);
    ts::write_file_atomically(out / "gentle_batches.csv", csv);  // after each batch: a stopped run keeps its rows
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
  write_contact_forces(world, stepper.settings(), out / "contact_forces.csv");
  ts::write_file_atomically(out / "silo_fill.csv",
                            fmt::format("grains,settle_s,fill_m,settle_wall_s\n{},{:.3f},{:.4f},{:.0f}\n", held.size(),
                                        settle_time, fill_height(), seconds));
}

// Granular column collapse (reference/column.toml scaled up): a column of `count` grains settled in
// a smooth cylinder of radius r0 (m) on a rough floor, then released by removing the cylinder; both
// phases run until the grains are at rest. H0 is the settled column's height, R_inf the deposit's
// radius (both the 95th percentile of the grains' outer extent: z + bounding radius, horizontal
// distance + bounding radius), r0 the cylinder's.
struct Collapse {
  double r0 = 0, h0 = 0, runout = 0;  // m
  std::size_t grains = 0;
  double settle_time = 0, spread_time = 0;  // s, simulated
  double seconds = 0;                       // wall
};

Collapse collapse_column(double r0, std::size_t count) {
  Scene scene = reference("column.toml");
  scene.emitters.at(0).radius = r0;
  scene.emitters.at(0).count = count;
  scene.boundaries.at(0).radius = r0 + 1e-4;
  // The rough floor reaches past the deposit: Lube's runout for a = 5 is 4.6 R0.
  const double floor = 2 * std::max(5.0 * r0, 1.8 * r0 + 0.3);
  scene.boundaries.at(1).size = Eigen::Vector2d(floor, floor);
  World world = make_world(scene);
  CpuStepper stepper = tall_scene_stepper(scene, world);
  const auto start = std::chrono::steady_clock::now();
  auto extent = [&](bool vertical) {
    std::vector<double> v;
    for (std::size_t b = 0; b < world.bodies.size(); ++b) {
      if (world.bodies.motion[b] != MotionType::Dynamic) continue;
      const Eigen::Vector3d& x = world.bodies.position[b];
      v.push_back((vertical ? x.z() : std::hypot(x.x(), x.y())) + world.bodies.bounding_radius[b]);
    }
    return percentile(v, 0.95);
  };
  const std::string label = fmt::format("column r0 = {:.3f} m", r0);
  Collapse c;
  // The filling is preparation: damped once the lattice has landed, as in the silo.
  const SettleDamping damping = damping_after_fall(scene, world);
  c.settle_time = run_until_rest(stepper, world, damping.from_time + 0.2, 2.5, 0.02, label + " settle",
                                 [&] { return extent(true); }, damping);
  c.r0 = r0;
  c.h0 = extent(true);
  world.walls.cylinders.clear();  // released
  c.spread_time = run_until_rest(stepper, world, 0.5, 2.5, 0.02, label + " spread", [&] { return extent(false); });
  c.runout = extent(false);
  c.grains = count;
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr, "column r0 = %.3f m, %zu grains: H0 = %.3f m, R_inf = %.3f m, %.1f s\n", r0, count, c.h0,
               c.runout, c.seconds);
  return c;
}

// Runout against aspect ratio: 20,000 grains per column, the cylinder's radius setting the aspect
// ratio (from 0.4 to 5.4; the break of Lube et al. is at 1.7): four columns on each side of the break
// (bench/validation/column_criteria.md). `radii` (m) runs only those columns.
void column(const fs::path& out, std::vector<double> radii) {
  if (radii.empty()) radii = {0.37, 0.32, 0.275, 0.25, 0.22, 0.195, 0.165, 0.15};
  std::string csv = "r0_m,grains,h0_m,runout_m,aspect,normalised_runout,settle_s,spread_s,seconds\n";
  for (double r0 : radii) {
    const Collapse c = collapse_column(r0, 20000);
    csv += fmt::format("{},{},{:.5f},{:.5f},{:.4f},{:.4f},{:.2f},{:.2f},{:.1f}\n", c.r0, c.grains, c.h0, c.runout,
                       c.h0 / c.r0, (c.runout - c.r0) / c.r0, c.settle_time, c.spread_time, c.seconds);
    ts::write_file_atomically(out / "column.csv", csv);  // after each column: a stopped run keeps its rows
  }
}

// The oedometer of assets/scenes/validation/oedometer.toml (bench/validation/oedometer_criteria.md) with
// `shape` "tetrahedra" (the scene's grains) or "spheres" (each grain one sphere of its volume and mass):
// the servo's log as oedometer_SHAPE.csv, and a row of oedometer_runs_SHAPE.csv. `scene_file`: a variant
// of that scene instead (e.g. oedometer_stiff.toml), none: the scene itself.
void oedometer(const fs::path& out, const std::string& shape, const fs::path& scene_file) {
  const Scene scene =
      load_scene(scene_file.empty() ? ts::bench::reference_scene("../validation/oedometer.toml") : scene_file);
  const bool spheres = shape == "spheres";
  const Run r = run(scene, out / "runs", "oedometer_" + shape, false, {},
                    spheres ? std::function<void(World&)>(grains_to_spheres) : std::function<void(World&)>());
  fs::copy_file(out / "runs" / ("oedometer_" + shape) / "servo.csv", out / ("oedometer_" + shape + ".csv"),
                fs::copy_options::overwrite_existing);
  ts::write_file_atomically(out / ("oedometer_runs_" + shape + ".csv"),
                            fmt::format("shape,grains,steps,seconds,grain_radius_m\n{},{},{},{:.1f},{}\n",
                                        shape, r.grains, r.steps, r.seconds, scene.grains.at(0).radius));
}

// Long runs of the GPU pipeline (float, on whatever GL device there is) against the CPU reference
// on the same scenes (issue 6, "long runs agree statistically"): the mu = 0.5 heap's angle, the 16 mm
// silo's discharge and the settled coarse bed (reference/coarse_bed.toml) for four fill seeds.
// `part` is heap, silo, bed or all; each part writes its own files.
void agreement(const fs::path& out, const std::string& part) {
  ts::gpu::Context context;
  const MakeStepper gpu = [&](const StepSettings& s) -> std::unique_ptr<Stepper> {
    return std::make_unique<GpuStepper>(context, s, Precision::Float, false);
  };
  ts::write_file_atomically(out / "agreement_renderer.txt", context.summary() + "\n");
  std::string silo_csv = "backend,seed,time_s,discharged\n";
  std::string bed_csv = "backend,seed,grains,mean_height_m\n";
  for (const bool on_gpu : {false, true}) {
    const std::string backend = on_gpu ? "gpu" : "cpu";
    const MakeStepper make = on_gpu ? gpu : MakeStepper{};
    if (part == "heap" || part == "all") {
      const Run heap = run(reference("heap.toml"), out / "runs", "agreement_heap_" + backend, false, make);
      ts::write_file_atomically(out / ("agreement_heap_" + backend + ".csv"), ts::bench::grain_centres_csv(heap.last));
    }
    if (part == "silo" || part == "all") {
      // Four fills (seed 5 is the scene's own): one discharge's rate scatters by several per cent.
      for (std::uint64_t seed : {5, 6, 7, 8}) {
        Scene scene = silo_scene(0.016);
        scene.emitters.at(0).seed = seed;
        const Run r = run(scene, out / "runs", fmt::format("agreement_silo{}_{}", seed, backend), true, make);
        silo_csv += discharge_rows(fmt::format("{},{}", backend, seed), r);
      }
    }
    if (part == "bed" || part == "all") {
      for (std::uint64_t seed = 1; seed <= 4; ++seed) {
        Scene scene = reference("coarse_bed.toml");
        scene.emitters.at(0).seed = seed;
        const Run bed = run(scene, out / "runs", fmt::format("agreement_bed{}_{}", seed, backend), false, make);
        double sum = 0;
        for (std::size_t b = 0; b < bed.last.bodies.size(); ++b) {
          if (bed.last.bodies.motion[b] == MotionType::Dynamic) sum += bed.last.bodies.position[b].z();
        }
        bed_csv += fmt::format("{},{},{},{:.6e}\n", backend, seed, bed.grains, sum / static_cast<double>(bed.grains));
      }
    }
  }
  if (part == "silo" || part == "all") ts::write_file_atomically(out / "agreement_silo.csv", silo_csv);
  if (part == "bed" || part == "all") ts::write_file_atomically(out / "agreement_bed.csv", bed_csv);
}

// The agreement's heap and silo on the GPU pipeline in fp64 (issue 44, item 4): `precision` "double"
// (Precision::Double, the mixed kernel: float contact arithmetic on double-differenced positions, double
// state and sums) or "full-double" (Precision::FullDouble, the all-double kernel it replaced), so the
// two can be compared on the decks' statistics (docs/benchmarks/sim.md "Mixed precision"). `part` is
// heap, silo or all; `silo_seeds` the silo's fill seeds (the agreement's are 5-8), `heap_seeds` the
// heap's pour seeds (the scene's own is 11; one pour's angle scatters by degrees, so several are
// averaged). Each precision writes its own files (mixed_heap_PRECISION_seedN.csv,
// mixed_silo_PRECISION.csv), so the two can run as separate processes; bench/validation/mixed_precision.py
// reads them.
void mixed_precision(const fs::path& out, const std::string& part, const std::string& precision,
                     const std::vector<std::uint64_t>& silo_seeds,
                     const std::vector<std::uint64_t>& heap_seeds) {
  if (precision != "double" && precision != "full-double") {
    throw std::runtime_error("mixed: precision '" + precision + "' is neither double nor full-double");
  }
  if (part != "heap" && part != "silo" && part != "all") {
    throw std::runtime_error("mixed: part '" + part + "' is none of heap, silo, all");
  }
  const Precision p = precision == "double" ? Precision::Double : Precision::FullDouble;
  ts::gpu::Context context;
  const MakeStepper make = [&](const StepSettings& s) -> std::unique_ptr<Stepper> {
    return std::make_unique<GpuStepper>(context, s, p, false);
  };
  ts::write_file_atomically(out / "mixed_renderer.txt", context.summary() + "\n");
  if (part == "heap" || part == "all") {
    for (const std::uint64_t seed : heap_seeds) {
      Scene scene = reference("heap.toml");
      scene.emitters.at(0).seed = seed;
      const std::string name = fmt::format("mixed_heap_{}_seed{}", precision, seed);
      const Run heap = run(scene, out / "runs", name, false, make);
      ts::write_file_atomically(out / (name + ".csv"), ts::bench::grain_centres_csv(heap.last));
    }
  }
  if (part == "silo" || part == "all") {
    std::string csv = "backend,seed,time_s,discharged\n";
    for (const std::uint64_t seed : silo_seeds) {
      Scene scene = silo_scene(0.016);
      scene.emitters.at(0).seed = seed;
      const Run r = run(scene, out / "runs", fmt::format("mixed_silo{}_{}", seed, precision), true, make);
      csv += discharge_rows(fmt::format("gpu-{},{}", precision, seed), r);
      // After each fill: a run stopped at its time cap keeps the fills it finished.
      ts::write_file_atomically(out / ("mixed_silo_" + precision + ".csv"), csv);
    }
  }
}

// "5,6" -> {5, 6}: fill seeds.
std::vector<std::uint64_t> seed_list(const std::string& text) {
  std::vector<std::uint64_t> seeds;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    if (item.empty() || item.find_first_not_of("0123456789") != std::string::npos) {
      throw std::runtime_error(
          fmt::format("mixed: seed '{}' is not a non-negative integer (expected e.g. 5,6,7,8)", item));
    }
    seeds.push_back(std::stoull(item));
    at = comma + 1;
  }
  return seeds;
}

// "0.32,0.25" -> {0.32, 0.25}: cylinder radii in metres, each within the floor the column lays out.
std::vector<double> radii_list(const std::string& text) {
  std::vector<double> radii;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    std::size_t used = 0;
    double r0 = 0;
    try {
      r0 = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || item.empty() || !(r0 >= 0.05 && r0 <= 1.0)) {
      throw std::runtime_error(fmt::format("column radii: '{}' is not a radius in metres within 0.05-1 "
                                           "(expected e.g. 0.32,0.25)", item));
    }
    radii.push_back(r0);
    at = comma + 1;
  }
  return radii;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(
        stderr,
        "usage: %s OUT_DIR [restitution|repose|silo "
        "[SCENE]|silo-spheres|silo[-spheres]-lammps|forces-backed|forces-gentle [BATCHES]|forces "
        "[GRAINS]|column [R0,R0,...]|all|agreement[-heap|-silo|-bed]|oedometer[-tetrahedra|-spheres] [SCENE]|"
        "mixed[-heap|-silo] [double|full-double] [SILO_SEEDS] [HEAP_SEEDS]]\n",
        argv[0]);
    return 2;
  }
  try {
    const fs::path out = argv[1];
    const std::string what = argc > 2 ? argv[2] : "all";
    fs::create_directories(out);
    if (what == "restitution" || what == "all") restitution(out);
    if (what == "repose" || what == "all") repose(out);
    if (what == "column" || what == "all") column(out, what == "column" && argc > 3 ? radii_list(argv[3]) : std::vector<double>{});
    if (what == "silo" || what == "all") silo(out, what == "silo" && argc > 3 ? fs::path(argv[3]) : fs::path());
    if (what == "forces" || what == "all") forces(out, what == "forces" && argc > 3 ? std::stoul(argv[3]) : 30000);
    if (what == "forces-backed") forces_backed(out);
    if (what == "forces-gentle") forces_gentle(out, argc > 3 ? std::stoul(argv[3]) : 8);
    if (what == "silo-spheres") silo(out, {}, true);
    if (what == "silo-lammps") silo_lammps(out, false);
    if (what == "silo-spheres-lammps") silo_lammps(out, true);
    if (what == "agreement") agreement(out, "all");
    const fs::path oedometer_scene = what.rfind("oedometer", 0) == 0 && argc > 3 ? fs::path(argv[3]) : fs::path();
    if (what == "oedometer" || what == "oedometer-tetrahedra") oedometer(out, "tetrahedra", oedometer_scene);
    if (what == "oedometer" || what == "oedometer-spheres") oedometer(out, "spheres", oedometer_scene);
    if (what.rfind("agreement-", 0) == 0) agreement(out, what.substr(10));
    if (what == "mixed" || what.rfind("mixed-", 0) == 0) {
      mixed_precision(out, what == "mixed" ? "all" : what.substr(6), argc > 3 ? argv[3] : "double",
                      seed_list(argc > 4 ? argv[4] : "5,6,7,8"),
                      seed_list(argc > 5 ? argv[5] : "11,12,13,14"));
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
