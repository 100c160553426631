// The runs behind docs/validation.md, through the library (CPU reference), written as CSV files that
// bench/validation/report.py plots and compares with the literature. Usage:
//   tetrasand_validation_runs OUT_DIR [restitution|repose|silo|all]
// Sized for a few minutes on two cores; the full-size versions (tens of thousands of grains) need
// the GPU pipeline on a real GPU (see docs/validation.md).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "sim/cpu_reference.h"
#include "sim/scene.h"
#include "sim/scene_runner.h"
#include "sim/time_step.h"

namespace {

namespace fs = std::filesystem;
using namespace ts::sim;

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

// The material block and grain of the scene runs: E = 1 MPa keeps the auto time step near 40 us.
std::string materials(double mu) {
  return fmt::format(R"(gravity = [0.0, 0.0, -9.81]
[[material]]
name = "sand"
E = 1.0e6
nu = 0.3
restitution = 0.5
mu = {}
gamma_s = 0.1
density = 2600.0
[grain]
radius = 1.0e-3
material = "sand"
)",
                     mu);
}

struct Run {
  World last;
  std::vector<std::pair<double, std::vector<double>>> heights;  // (time, grain centre heights)
  double seconds = 0;
  std::int64_t steps = 0;
  std::size_t grains = 0;
};

Run run(const std::string& text, const fs::path& dir, const std::string& name, bool record_heights) {
  fs::create_directories(dir);
  const Scene scene = parse_scene(text, dir / (name + ".toml"));
  Run r;
  RunHooks hooks;
  hooks.on_output = [&](const World& world, const StepStats&, std::int64_t) {
    if (!record_heights) return;
    std::vector<double> z;
    for (std::size_t b = 0; b < world.bodies.size(); ++b) {
      if (world.bodies.motion[b] == MotionType::Dynamic) z.push_back(world.bodies.position[b].z());
    }
    r.heights.emplace_back(world.time, std::move(z));
  };
  World* last = &r.last;
  auto base = hooks.on_output;
  hooks.on_output = [&, last](const World& world, const StepStats& s, std::int64_t step) {
    base(world, s, step);
    *last = world;
  };
  const auto start = std::chrono::steady_clock::now();
  const RunResult result = run_scene(scene, dir / name, hooks);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.steps = result.steps;
  r.grains = result.grains;
  std::fprintf(stderr, "%s: %zu grains, %lld steps, %.1f s\n", name.c_str(), r.grains,
               static_cast<long long>(r.steps), r.seconds);
  return r;
}

// Grains poured from a 1.6 cm x 1.6 cm box 3-6 cm above a rough floor with no side walls pile up
// into a heap; its surface slope is the angle of repose. Also writes the resting pile's contact forces.
void repose(const fs::path& out) {
  std::string csv = "mu,grains,seconds\n";
  for (double mu : {0.1, 0.3, 0.5, 0.8}) {
    const std::string text = materials(mu) + R"(
[[emitter]]
type = "pour"
min = [-0.008, -0.008, 0.03]
max = [0.008, 0.008, 0.06]
count = 400
rate = 1000.0
seed = 11
[[boundary]]
type = "plane"
rough = true
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
size = [0.12, 0.12]
particle_radius = 1.0e-3
material = "sand"
[simulation]
duration = 0.8
dt = "auto"
[output]
every = 2000
csv = false
)";
    const Run r = run(text, out / "runs", fmt::format("repose_mu{}", mu), false);
    // The resting heap's grain centres; report.py measures its slope (bench/peers/sim_peers.py).
    std::string heap = "x_m,y_m,z_m\n";
    for (std::size_t b = 0; b < r.last.bodies.size(); ++b) {
      if (r.last.bodies.motion[b] != MotionType::Dynamic) continue;
      const Eigen::Vector3d& x = r.last.bodies.position[b];
      heap += fmt::format("{:.6e},{:.6e},{:.6e}\n", x.x(), x.y(), x.z());
    }
    ts::write_file_atomically(out / fmt::format("heap_mu{}.csv", mu), heap);
    csv += fmt::format("{},{},{:.1f}\n", mu, r.grains, r.seconds);
    if (mu == 0.5) {
      // Normal contact forces of the resting heap (grain-grain and grain-floor particle contacts).
      StepSettings settings;
      settings.dt = 1e-5;
      CpuStepper stepper(r.last, settings);
      const std::vector<Eigen::Vector3d> x = particle_positions(r.last);
      std::string forces = "normal_force_N\n";
      for (const ContactRecord& c : stepper.contacts(r.last)) {
        if (c.partner < 0) continue;
        const Eigen::Vector3d normal = (x[c.particle] - x[static_cast<std::size_t>(c.partner)]).normalized();
        forces += fmt::format("{:.6e}\n", std::abs(c.force.dot(normal)));
      }
      ts::write_file_atomically(out / "contact_forces.csv", forces);
    }
  }
  ts::write_file_atomically(out / "repose.csv", csv);
}

// A flat-bottomed silo (smooth cylinder, rough plate with a round orifice of diameter D): grains
// below the plate over time; the steady discharge rate is fitted by report.py.
void silo(const fs::path& out) {
  std::string csv = "orifice_m,time_s,discharged\n";
  std::string info = "orifice_m,grains,seconds\n";
  for (double d : {0.012, 0.016, 0.020}) {
    const std::string text = materials(0.5) + fmt::format(R"(
[[emitter]]
type = "column"
centre = [0.0, 0.0, 0.002]
radius = 0.0195
count = 600
seed = 5
[[boundary]]
type = "cylinder"
centre = [0.0, 0.0]
radius = 0.02
z_min = 0.0
z_max = 0.3
material = "sand"
[[boundary]]
type = "plane"
rough = true
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
size = [0.042, 0.042]
hole_radius = {}
particle_radius = 1.0e-3
material = "sand"
[simulation]
duration = 0.6
dt = "auto"
[output]
every = 250
csv = false
)",
                                                          d / 2);
    const Run r = run(text, out / "runs", fmt::format("silo_D{}", d), true);
    for (const auto& [t, z] : r.heights) {
      csv += fmt::format("{},{:.5f},{}\n", d, t, std::count_if(z.begin(), z.end(), [](double h) { return h < -2e-3; }));
    }
    info += fmt::format("{},{},{:.1f}\n", d, r.grains, r.seconds);
  }
  ts::write_file_atomically(out / "silo.csv", csv);
  ts::write_file_atomically(out / "silo_runs.csv", info);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR [restitution|repose|silo|all]\n", argv[0]);
    return 2;
  }
  try {
    const fs::path out = argv[1];
    const std::string what = argc > 2 ? argv[2] : "all";
    fs::create_directories(out);
    if (what == "restitution" || what == "all") restitution(out);
    if (what == "repose" || what == "all") repose(out);
    if (what == "silo" || what == "all") silo(out);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
