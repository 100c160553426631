// The runs behind docs/validation.md, through the library (CPU reference; the agreement run also on
// the GPU pipeline), written as CSV files that
// bench/validation/report.py plots and compares with the literature. Usage:
//   tetrasand_validation_runs OUT_DIR [restitution|repose|silo|column|agreement[-heap|-silo|-bed]|all]
// Sized for a few minutes on two cores; the full-size versions (tens of thousands of grains) need
// the GPU pipeline on a real GPU (see docs/validation.md).
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
#include <string>
#include <vector>

#include "bench/bench_scenes.h"
#include "core/atomic_file.h"
#include "gpu/context.h"
#include "sim/cpu_reference.h"
#include "sim/gpu_stepper.h"
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

using MakeStepper = std::function<std::unique_ptr<Stepper>(const StepSettings&)>;

// Runs `scene` (on the CPU reference unless `make` says otherwise) with no files but the runner's own.
Run run(Scene scene, const fs::path& dir, const std::string& name, bool record_heights, const MakeStepper& make = {}) {
  fs::create_directories(dir);
  scene.output.csv = false;
  scene.output.ply = false;
  Run r;
  RunHooks hooks;
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

// Grains poured from a 1.6 cm x 1.6 cm box 3-6 cm above a rough floor with no side walls pile up
// into a heap (reference/heap.toml); its surface slope is the angle of repose. Also writes the
// resting pile's contact forces.
void repose(const fs::path& out) {
  std::string csv = "mu,grains,seconds\n";
  for (double mu : {0.1, 0.3, 0.5, 0.8}) {
    Scene scene = reference("heap.toml");
    set_friction(scene, mu);
    const Run r = run(scene, out / "runs", fmt::format("repose_mu{}", mu), false);
    ts::write_file_atomically(out / fmt::format("heap_mu{}.csv", mu), ts::bench::grain_centres_csv(r.last));
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

// A flat-bottomed silo (smooth cylinder, rough plate with a round orifice of diameter D): grains
// below the plate over time; the steady discharge rate is fitted by report.py.
void silo(const fs::path& out) {
  std::string csv = "orifice_m,time_s,discharged\n";
  std::string info = "orifice_m,grains,seconds\n";
  for (double d : {0.012, 0.016, 0.020}) {
    const Run r = run(silo_scene(d), out / "runs", fmt::format("silo_D{}", d), true);
    csv += discharge_rows(fmt::format("{}", d), r);
    info += fmt::format("{},{},{:.1f}\n", d, r.grains, r.seconds);
  }
  ts::write_file_atomically(out / "silo.csv", csv);
  ts::write_file_atomically(out / "silo_runs.csv", info);
}

// Granular column collapse (reference/column.toml): a column of `count` grains settled in a smooth
// cylinder of radius r0 (m) on a rough floor, then released by removing the cylinder. H0 is the
// settled column's height, R_inf the deposit's radius (both the 95th percentile of the grains'
// outer extent: z + bounding radius, horizontal distance + bounding radius), r0 the cylinder's.
struct Collapse {
  double r0 = 0, h0 = 0, runout = 0;  // m
  std::size_t grains = 0;
  double seconds = 0;
};

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

Collapse collapse_column(double r0, std::size_t count) {
  Scene scene = reference("column.toml");
  scene.emitters.at(0).radius = r0;
  scene.emitters.at(0).count = count;
  scene.boundaries.at(0).radius = r0 + 1e-4;
  World world = make_world(scene);
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, world, nullptr);
  const auto steps = static_cast<std::int64_t>(std::ceil(scene.simulation.duration / settings.dt));
  const auto start = std::chrono::steady_clock::now();
  CpuStepper stepper(world, settings);
  auto extent = [&](bool vertical) {
    std::vector<double> v;
    for (std::size_t b = 0; b < world.bodies.size(); ++b) {
      if (world.bodies.motion[b] != MotionType::Dynamic) continue;
      const Eigen::Vector3d& x = world.bodies.position[b];
      v.push_back((vertical ? x.z() : std::hypot(x.x(), x.y())) + world.bodies.bounding_radius[b]);
    }
    return percentile(v, 0.95);
  };
  for (std::int64_t s = 0; s < steps; ++s) stepper.step(world);
  Collapse c;
  c.r0 = r0;
  c.h0 = extent(true);
  world.walls.cylinders.clear();  // released
  for (std::int64_t s = 0; s < steps; ++s) stepper.step(world);
  c.runout = extent(false);
  c.grains = count;
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr, "column r0 = %.3f m, %zu grains: H0 = %.3f m, R_inf = %.3f m, %.1f s\n", r0, count, c.h0,
               c.runout, c.seconds);
  return c;
}

// Runout against aspect ratio: 400 grains per column, the radius setting the aspect ratio.
void column(const fs::path& out) {
  std::string csv = "r0_m,grains,h0_m,runout_m,aspect,normalised_runout,seconds\n";
  for (double r0 : {0.10, 0.075, 0.06, 0.045}) {
    const Collapse c = collapse_column(r0, 400);
    csv += fmt::format("{},{},{:.5f},{:.5f},{:.4f},{:.4f},{:.1f}\n", c.r0, c.grains, c.h0, c.runout, c.h0 / c.r0,
                       (c.runout - c.r0) / c.r0, c.seconds);
  }
  ts::write_file_atomically(out / "column.csv", csv);
}

// Long runs of the GPU pipeline (float, on whatever GL device there is) against the CPU reference
// on the same scenes (issue 6, "long runs agree statistically"): the mu = 0.5 heap's angle, the 16 mm
// silo's discharge and the settled coarse bed (reference/coarse_bed.toml) for four fill seeds.
// `part` is heap, silo, bed or all; each part writes its own files.
void agreement(const fs::path& out, const std::string& part) {
  ts::gpu::Context context;
  const MakeStepper gpu = [&](const StepSettings& s) -> std::unique_ptr<Stepper> {
    return std::make_unique<GpuPipelineStepper>(context, s, Precision::Float, false);
  };
  ts::write_file_atomically(out / "agreement_renderer.txt", context.summary() + "\n");
  std::string silo_csv = "backend,time_s,discharged\n";
  std::string bed_csv = "backend,seed,grains,mean_height_m\n";
  for (const bool on_gpu : {false, true}) {
    const std::string backend = on_gpu ? "gpu" : "cpu";
    const MakeStepper make = on_gpu ? gpu : MakeStepper{};
    if (part == "heap" || part == "all") {
      const Run heap = run(reference("heap.toml"), out / "runs", "agreement_heap_" + backend, false, make);
      ts::write_file_atomically(out / ("agreement_heap_" + backend + ".csv"), ts::bench::grain_centres_csv(heap.last));
    }
    if (part == "silo" || part == "all") {
      silo_csv += discharge_rows(backend, run(silo_scene(0.016), out / "runs", "agreement_silo_" + backend, true, make));
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

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR [restitution|repose|silo|column|agreement[-heap|-silo|-bed]|all]\n", argv[0]);
    return 2;
  }
  try {
    const fs::path out = argv[1];
    const std::string what = argc > 2 ? argv[2] : "all";
    fs::create_directories(out);
    if (what == "restitution" || what == "all") restitution(out);
    if (what == "repose" || what == "all") repose(out);
    if (what == "silo" || what == "all") silo(out);
    if (what == "column" || what == "all") column(out);
    if (what == "agreement" || what == "all") agreement(out, "all");
    if (what.rfind("agreement-", 0) == 0) agreement(out, what.substr(10));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
