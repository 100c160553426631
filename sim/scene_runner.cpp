#include "sim/scene_runner.h"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "sim/cpu_reference.h"
#include "sim/scene_world.h"

namespace ts::sim {

double resolve_time_step(const Scene& scene, const World& world, std::string* warning) {
  const TimeStepBound bound = scene_time_step_bound(scene, world);
  const double dt = scene.simulation.dt <= 0 ? bound.recommended : scene.simulation.dt;
  // Forward Euler gains energy in every contact: about t_c/400 keeps restitution within 2 %
  // (tests/sim/extremes_test.cpp); at t_c/20 e = 0.65 comes out as 0.86.
  if (scene.simulation.step.integrator == Integrator::ForwardEuler && dt > bound.contact_duration / 400) {
    log::warn("{}: forward Euler at {:.3g} steps per contact overestimates restitution (2 % needs about 400); "
              "integrator = \"symplectic\" is accurate at the automatic step",
              scene.file.string(), bound.contact_duration / dt);
  }
  // The tangential spring is undamped but for gamma_s, so forward Euler pumps it the same way: a
  // 300-grain pile poured with springs came out at 6.3 degrees, 14.7 with symplectic Euler.
  if (scene.simulation.step.integrator == Integrator::ForwardEuler &&
      scene.simulation.step.tangential == TangentialModel::Spring) {
    log::warn("{}: tangential = \"spring\" with forward Euler gains energy in every tangential oscillation "
              "(poured piles come out far too flat); use integrator = \"symplectic\"",
              scene.file.string());
  }
  if (scene.simulation.dt <= 0) return bound.recommended;
  const std::string message = check_time_step(scene.simulation.dt, bound);
  if (warning) *warning = message;
  return scene.simulation.dt;
}

void write_particles_ply(const World& world, const std::filesystem::path& file) {
  const std::vector<Eigen::Vector3d> positions = particle_positions(world);
  std::string bytes = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment tetrasand particles, SI units (m), t = {:.9g} s\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float radius\n"
      "property uint body\nend_header\n",
      world.time, positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const float v[4] = {float(positions[i].x()), float(positions[i].y()), float(positions[i].z()),
                        float(world.particles.radius[i])};
    const std::uint32_t body = world.particles.body[i];
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
    bytes.append(reinterpret_cast<const char*>(&body), sizeof body);
  }
  write_file_atomically(file, bytes);
}

void write_particles_vtp(const World& world, const std::filesystem::path& file) {
  const std::vector<Eigen::Vector3d> positions = particle_positions(world);
  std::string points, radii, bodies, connectivity, offsets;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    points += fmt::format("{:.9g} {:.9g} {:.9g}\n", positions[i].x(), positions[i].y(), positions[i].z());
    radii += fmt::format("{:.9g}\n", world.particles.radius[i]);
    bodies += fmt::format("{}\n", world.particles.body[i]);
    connectivity += fmt::format("{}\n", i);
    offsets += fmt::format("{}\n", i + 1);
  }
  const std::string xml = fmt::format(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "<PolyData>\n<Piece NumberOfPoints=\"{0}\" NumberOfVerts=\"{0}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      "NumberOfPolys=\"0\">\n"
      "<PointData Scalars=\"radius\">\n<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n{1}</DataArray>\n"
      "<DataArray type=\"UInt32\" Name=\"body\" format=\"ascii\">\n{2}</DataArray>\n</PointData>\n"
      "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n{3}</DataArray>\n</Points>\n"
      "<Verts>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n{4}</DataArray>\n"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n{5}</DataArray>\n</Verts>\n"
      "</Piece>\n</PolyData>\n</VTKFile>\n",
      positions.size(), radii, bodies, points, connectivity, offsets);
  write_file_atomically(file, xml);
}

void write_contacts_csv(const std::vector<ContactRecord>& contacts, const std::filesystem::path& file) {
  std::string csv = "particle,partner,x_m,y_m,z_m,fx_N,fy_N,fz_N,overlap_m\n";
  for (const ContactRecord& c : contacts) {
    csv += fmt::format("{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", c.particle, c.partner, c.point.x(),
                       c.point.y(), c.point.z(), c.force.x(), c.force.y(), c.force.z(), c.overlap);
  }
  write_file_atomically(file, csv);
}

namespace {

std::size_t dynamic_bodies(const World& world) {
  std::size_t n = 0;
  for (MotionType m : world.bodies.motion) n += m == MotionType::Dynamic ? 1 : 0;
  return n;
}

class OutputWriter {
 public:
  OutputWriter(const Scene& scene, const std::filesystem::path& dir, const RunHooks& hooks)
      : settings_(scene.output), dir_(dir), hooks_(hooks) {
    std::filesystem::create_directories(dir_);
    csv_ = "step,time_s,grains,kinetic_translational_J,kinetic_rotational_J,potential_J,elastic_J,contacts,"
           "wall_contacts,max_overlap_ratio,velocity_clamps,angular_velocity_clamps,overlap_clamps,spring_overflows\n";
  }

  void write(const World& world, const StepStats& stats, std::int64_t step, Stepper& stepper) {
    const std::string index = fmt::format("{:06d}", frame_);
    if (settings_.csv) {
      csv_ += fmt::format("{},{:.9g},{},{:.9g},{:.9g},{:.9g},{:.9g},{},{},{:.6g},{},{},{},{}\n", step, world.time,
                          dynamic_bodies(world), stats.energy.translational, stats.energy.rotational,
                          stats.energy.potential, stats.elastic_energy, stats.contacts, stats.wall_contacts,
                          stats.max_overlap_ratio, stats.velocity_clamps, stats.angular_velocity_clamps,
                          stats.overlap_clamps, stats.spring_overflows);
      write_file_atomically(dir_ / "metrics.csv", csv_);  // whole file each time: valid after any interruption
    }
    if (settings_.ply) write_particles_ply(world, dir_ / ("particles_" + index + ".ply"));
    if (settings_.vtp) write_particles_vtp(world, dir_ / ("particles_" + index + ".vtp"));
    if (settings_.contacts) write_contacts_csv(stepper.contacts(world), dir_ / ("contacts_" + index + ".csv"));
    if (settings_.frames) {
      if (hooks_.write_frame) {
        hooks_.write_frame(world, frame_, dir_);
      } else if (frame_ == 0) {
        log::warn("[output] frames = true, but this run has no frame renderer: no PNG frames are written");
      }
    }
    if (hooks_.on_output) hooks_.on_output(world, stats, step);
    ++frame_;
  }

  std::int64_t count() const { return frame_; }

 private:
  OutputSettings settings_;
  std::filesystem::path dir_;
  const RunHooks& hooks_;
  std::string csv_;
  std::int64_t frame_ = 0;
};

}  // namespace

RunResult run_scene(const Scene& scene, const std::filesystem::path& output_dir, const RunHooks& hooks,
                    const StepperFactory& make_stepper) {
  World world = make_world(scene);
  RunResult result;
  result.dt = resolve_time_step(scene, world, &result.time_step_warning);
  if (!result.time_step_warning.empty()) log::warn("{}: {}", scene.file.string(), result.time_step_warning);
  StepSettings settings = scene.simulation.step;
  settings.dt = result.dt;
  std::unique_ptr<Stepper> stepper =
      make_stepper ? make_stepper(settings) : std::make_unique<CpuStepper>(settings);

  std::vector<PourEmitter> pours;
  std::int64_t emit_every = scene.output.every;  // steps between pour checks: about twice per release
  for (const Emitter& e : scene.emitters) {
    if (e.type != EmitterType::Pour) continue;
    pours.emplace_back(scene, e);
    emit_every = std::min(emit_every, std::max<std::int64_t>(1, std::llround(0.5 / (e.rate * result.dt))));
  }
  auto pouring = [&] {
    return std::any_of(pours.begin(), pours.end(), [](const PourEmitter& p) { return !p.finished(); });
  };
  auto emit = [&] {
    std::size_t added = 0;
    for (PourEmitter& p : pours) added += p.emit(world);
    return added;
  };

  emit();
  stepper->load(world);
  OutputWriter output(scene, output_dir, hooks);
  const auto total = static_cast<std::int64_t>(std::ceil(scene.simulation.duration / result.dt - 1e-9));
  StepStats stats;
  stats.energy = energy(world);
  output.write(world, stats, 0, *stepper);
  std::int64_t step = 0;
  std::size_t velocity_clamps = 0, angular_clamps = 0, overlap_clamps = 0, overflows = 0;  // since the last output
  while (step < total) {
    if (step > 0 && pouring() && emit() > 0) stepper->load(world);
    const std::int64_t next_output = std::min(total, (step / scene.output.every + 1) * scene.output.every);
    const std::int64_t chunk = std::min(next_output - step, pouring() ? emit_every : next_output - step);
    const World last_good = world;
    try {
      stats = stepper->advance(world, chunk);
    } catch (const Error& e) {
      if (e.code() == ExitCode::Unstable) write_particles_ply(last_good, output_dir / "last_good.ply");
      throw;
    }
    step += chunk;
    velocity_clamps += stats.velocity_clamps;
    angular_clamps += stats.angular_velocity_clamps;
    overlap_clamps += stats.overlap_clamps;
    overflows += stats.spring_overflows;
    result.spring_overflows += stats.spring_overflows;
    if (step == next_output) {
      stats.spring_overflows = std::exchange(overflows, 0);
      stats.velocity_clamps = std::exchange(velocity_clamps, 0);
      stats.angular_velocity_clamps = std::exchange(angular_clamps, 0);
      stats.overlap_clamps = std::exchange(overlap_clamps, 0);
      output.write(world, stats, step, *stepper);
    }
  }
  result.steps = step;
  result.last = stats;
  result.grains = dynamic_bodies(world);
  result.outputs = output.count();
  if (hooks.on_finish) hooks.on_finish(*stepper);
  return result;
}

}  // namespace ts::sim
