#include "scene/scene_runner.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/checked_values.h"
#include "core/error.h"
#include "core/log.h"
#include "core/text_tokens.h"
#include "scene/checkpoint.h"
#include "scene/fragments.h"
#include "scene/scene_drivers.h"
#include "scene/scene_checks.h"
#include "scene/scene_world.h"
#include "scene/vtk_files.h"
#include "scene/servo.h"
#include "sim/cpu_stepper.h"

namespace ts::scene {

namespace {

int line_of_key(const Scene& scene, const std::string& key) {
  const auto it = scene.key_lines.find(key);
  return it == scene.key_lines.end() ? 0 : it->second;
}

}  // namespace

double resolve_time_step(const Scene& scene, const World& world, std::string* warning, TimeStepBound* bound_used) {
  const TimeStepBound bound = scene_time_step_bound(scene, world);
  if (bound_used) *bound_used = bound;
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
  if (scene.simulation.check_time_step && scene.simulation.dt > kHandTimeStepFactor * bound.recommended) {
    throw InputError(fmt::format(
        "{}: {}: {:.3g} times the bound, where a time step by hand may exceed it by at most {:g}x "
        "(docs/reliability.md); use dt <= {:.3g} s or dt = \"auto\", or check_time_step = false in "
        "[simulation] to run it anyway with a warning",
        scene_location(scene, "simulation.dt"), message, scene.simulation.dt / bound.recommended,
        kHandTimeStepFactor, kHandTimeStepFactor * bound.recommended));
  }
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

void write_contacts_csv(const std::vector<ContactRecord>& contacts, const std::filesystem::path& file) {
  std::string csv = "particle,partner,x_m,y_m,z_m,fx_N,fy_N,fz_N,overlap_m\n";
  for (const ContactRecord& c : contacts) {
    csv += fmt::format("{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", c.particle, c.partner, c.point.x(),
                       c.point.y(), c.point.z(), c.force.x(), c.force.y(), c.force.z(), c.overlap);
  }
  write_file_atomically(file, csv);
}

namespace {

// The `tetrasand sim` options that choose an engine (Stepper::engine()), for a resume's error.
std::string engine_flags(const std::string& engine) {
  if (engine == "cpu reference") return "--backend cpu";
  if (engine == "gpu double") return "--backend gpu --precision double";
  if (engine == "gpu float") return "--backend gpu";
  return "the engine's options";
}

std::size_t bodies_moving(const World& world, MotionType motion) {
  return static_cast<std::size_t>(std::count(world.bodies.motion.begin(), world.bodies.motion.end(), motion));
}

std::size_t props_moving(const Scene& scene, MotionType motion) {
  return static_cast<std::size_t>(std::count_if(scene.props.begin(), scene.props.end(),
                                                [motion](const Prop& p) { return p.motion == motion; }));
}

// Dynamic bodies of the props: one a rigid prop, one a sphere of a breakable prop.
std::size_t dynamic_prop_bodies(const Scene& scene) {
  std::size_t bodies = 0;
  for (const Prop& p : scene.props) bodies += p.motion == MotionType::Dynamic ? prop_body_count(p) : 0;
  return bodies;
}

// Grains are the dynamic bodies that are not props (emitters only add grains).
std::size_t grains_of(const Scene& scene, const World& world) {
  return bodies_moving(world, MotionType::Dynamic) - dynamic_prop_bodies(scene);
}

constexpr std::string_view kMetricsHeader =
    "step,time_s,grains,kinetic_translational_J,kinetic_rotational_J,potential_J,elastic_J,contacts,"
    "wall_contacts,max_overlap_ratio,velocity_clamps,angular_velocity_clamps,overlap_clamps,spring_overflows,"
    "bonds,bonds_broken,fragments,largest_fragment_kg\n";

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

bool is_finite_number(std::string_view field) {
  const std::optional<double> v = detail::parse_number(field);
  return v && std::isfinite(*v);
}

void check_metrics_csv(std::string_view csv, std::int64_t rows) {
  if (!csv.starts_with(kMetricsHeader)) throw InputError("metrics_csv: its header is not metrics.csv's");
  const std::size_t columns = static_cast<std::size_t>(std::count(kMetricsHeader.begin(), kMetricsHeader.end(), ',')) + 1;
  std::int64_t row = 0;
  for (std::size_t at = kMetricsHeader.size(); at < csv.size(); ++row) {
    const std::size_t end = csv.find('\n', at);
    if (end == std::string_view::npos) throw InputError(fmt::format("metrics_csv: row {} has no line end", row + 1));
    const std::vector<std::string_view> fields = split_fields(csv.substr(at, end - at));
    const bool finite = std::all_of(fields.begin(), fields.end(), [](std::string_view f) { return is_finite_number(f); });
    if (fields.size() != columns || !finite)
      throw InputError(fmt::format("metrics_csv: row {} is not {} finite numbers", row + 1, columns));
    at = end + 1;
  }
  if (row != rows) throw InputError(fmt::format("metrics_csv: {} rows for {} outputs", row, rows));
}

class OutputWriter {
 public:
  OutputWriter(const Scene& scene, const std::filesystem::path& dir, const RunHooks& hooks)
      : scene_(scene), dir_(dir), hooks_(hooks) {
    std::filesystem::create_directories(dir_);
    csv_ = kMetricsHeader;
  }

  void write(const World& world, const StepStats& stats, std::int64_t step, Stepper& stepper) {
    const std::string index = fmt::format("{:06d}", frame_);
    if (scene_.output.csv) {
      const BondCounts bonds = count_bonds(scene_, world);
      csv_ += fmt::format("{},{:.9g},{},{:.9g},{:.9g},{:.9g},{:.9g},{},{},{:.6g},{},{},{},{},{},{},{},{:.9g}\n", step,
                          world.time, grains_of(scene_, world), stats.energy.translational,
                          stats.energy.rotational, stats.energy.potential, stats.elastic_energy,
                          stats.contacts, stats.wall_contacts, stats.max_overlap_ratio, stats.velocity_clamps,
                          stats.angular_velocity_clamps, stats.overlap_clamps, stats.spring_overflows,
                          bonds.intact, bonds.broken, bonds.fragments, bonds.largest_fragment_mass);
      write_file_atomically(dir_ / "metrics.csv", csv_);  // whole file each time: valid after any interruption
    }
    if (scene_.output.ply) write_particles_ply(world, dir_ / ("particles_" + index + ".ply"));
    if (scene_.output.vtp) {
      write_particles_vtp(world, dir_ / ("particles_" + index + ".vtp"));
      vtp_collection_.add("particles_" + index + ".vtp", world.time);
    }
    if (scene_.output.contacts)
      write_contacts_csv(stepper.contacts(world), dir_ / ("contacts_" + index + ".csv"));
    if (scene_.output.frames) {
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
  const std::string& csv() const { return csv_; }
  // Every kind of output the folder holds, each with as many files as outputs were written (a resumed
  // run's included: its frame counter goes on from the checkpoint's).
  std::vector<OutputRecord> files() const {
    std::vector<OutputRecord> files;
    if (scene_.output.csv) files.push_back({"metrics.csv", frame_, "rows"});
    if (scene_.output.ply) files.push_back({"particles_NNNNNN.ply", frame_, "files"});
    if (scene_.output.vtp) files.push_back({"particles_NNNNNN.vtp", frame_, "files"});
    if (scene_.output.vtp) files.push_back({"particles.pvd", frame_, "entries"});
    if (scene_.output.contacts) files.push_back({"contacts_NNNNNN.csv", frame_, "files"});
    if (scene_.output.frames && hooks_.write_frame) files.push_back({"frame_NNNNNN.png", frame_, "files"});
    return files;
  }
  // Goes on after `frames` outputs whose metrics.csv was `csv` (a resumed run). The text comes from
  // a checkpoint, so it is checked as this writer would have written it: the header, one row per
  // output (none without [output] csv), each of finite numbers; a crafted checkpoint put text into
  // metrics.csv that the run then reported at exit 0 (found by fuzz_checkpoint).
  void restore(std::string csv, std::int64_t frames) {
    check_metrics_csv(csv, scene_.output.csv ? frames : 0);
    csv_ = std::move(csv);
    frame_ = frames;
    if (scene_.output.vtp) vtp_collection_.restore(frames);
  }

 private:
  const Scene& scene_;
  std::filesystem::path dir_;
  const RunHooks& hooks_;
  std::string csv_;
  std::int64_t frame_ = 0;
  VtpCollection vtp_collection_{dir_ / "particles.pvd"};
};

using Clock = std::chrono::steady_clock;

// A run from its first step or from a checkpoint to the end. Steps go in stretches that end where
// an output is due or, while pouring, where emitters release grains, exactly as without checkpoints;
// a checkpoint or the wall clock may split a stretch, which changes no bit (an engine's advance(a)
// then advance(b) is advance(a + b), and emitters release only where a stretch starts).
class SceneRun {
 public:
  SceneRun(const Scene& scene, const std::filesystem::path& dir, const RunHooks& hooks,
           const StepperFactory& make_stepper, const RunControl& control)
      : scene_(scene),
        dir_(dir),
        hooks_(hooks),
        make_stepper_(make_stepper),
        control_(control),
        watch_(scene.simulation.check_clamps) {}

  RunResult run();

 private:
  bool checkpointing() const {
    return scene_.output.checkpoint_every > 0 || scene_.output.checkpoint_seconds > 0;
  }
  void prepare(const World& initial);
  void start_fresh();
  void resume();
  void restore(const RunState& state, const std::filesystem::path& file);
  void begin_stretch();
  std::int64_t stop_at() const;
  void advance_to(std::int64_t until);
  void end_stretch();
  void checkpoint_if_due();
  RunState state() const;

  const Scene& scene_;
  std::filesystem::path dir_;
  const RunHooks& hooks_;
  const StepperFactory& make_stepper_;
  RunControl control_;
  World world_, last_good_;
  WorldSources sources_;
  RunResult result_;
  std::unique_ptr<Stepper> stepper_;
  std::optional<SceneDrivers> drivers_;  // the pour emitters and the props' servos
  std::optional<OutputWriter> output_;
  std::string hash_;     // of the scene, for checkpoints
  double duration_ = 0;  // s
  std::int64_t total_ = 0, step_ = 0, stretch_end_ = 0, stretch_output_ = 0, last_output_step_ = 0;
  StepStats stats_;
  // Counts since the last output (velocity, angular, overlap, spring overflows).
  std::size_t velocity_clamps_ = 0, angular_clamps_ = 0, overlap_clamps_ = 0, overflows_ = 0;
  ClampWatch watch_;
  Clock::time_point last_checkpoint_ = Clock::now();
  std::int64_t clock_stretch_ = 1;  // steps between looks at the wall clock (checkpoint_seconds)
};

// The time step, the force checks, the engine and the pour emitters, from the initial world.
void SceneRun::prepare(const World& initial) {
  result_.dt = resolve_time_step(scene_, initial, &result_.time_step_warning, &result_.bound);
  result_.bonds_at_start = count_bonds(scene_, initial).intact;
  if (!result_.time_step_warning.empty())
    log::warn("{}: {}", scene_.file.string(), result_.time_step_warning);
  check_scene_forces(scene_, initial, sources_, result_.dt);
  StepSettings settings = scene_.simulation.step;
  settings.dt = result_.dt;
  settings.design_speed = scene_design_speed(scene_, initial).speed;  // picks the contact lists' skin
  stepper_ = make_stepper_ ? make_stepper_(settings) : std::make_unique<CpuStepper>(settings);
  drivers_.emplace(scene_, sources_, result_.dt);
  if (checkpointing()) hash_ = scene_hash(scene_, initial);
}

void SceneRun::start_fresh() {
  world_ = make_world(scene_, &sources_);
  if (hooks_.edit_initial_world) hooks_.edit_initial_world(world_);
  prepare(world_);
  duration_ = control_.duration > 0 ? control_.duration : scene_.simulation.duration;
  drivers_->emit(world_);
  stepper_->load(world_);
  output_.emplace(scene_, dir_, hooks_);
  remove_checkpoints(dir_);
  stats_.energy = energy(world_);
  output_->write(world_, stats_, 0, *stepper_);
}

// What the scene fixes for the whole run (gravity, smooth walls, materials) must come back as the
// scene gives it: the checkpoint's own copy is only checked for finite values, and a crafted one
// with gravity of 1e231 resumed to exit 0 with particles 1e227 cells out (found by fuzz_checkpoint).
void check_scene_constants(const World& resumed, const World& initial, const std::filesystem::path& file) {
  const auto differs = [&](std::string_view what) {
    throw InputError(file, fmt::format("its {} differ from the scene's (the checkpoint was changed after "
                                       "writing, or belongs to another scene)",
                                       what));
  };
  if (resumed.gravity != initial.gravity) differs("gravity");
  if (resumed.walls.planes != initial.walls.planes || resumed.walls.cylinders != initial.walls.cylinders)
    differs("smooth walls");
  if (resumed.materials != initial.materials) differs("materials");
}

void SceneRun::resume() {
  World initial = make_world(scene_, &sources_);
  if (hooks_.edit_initial_world) hooks_.edit_initial_world(initial);
  prepare(initial);
  std::filesystem::path file;
  const RunState state = read_latest_checkpoint(dir_, &file);
  if (state.scene_hash != scene_hash(scene_, initial)) {
    throw InputError(file,
                     fmt::format("written for another scene: {} (or a prop's body) changed since, or is "
                                 "another file; resume with the scene the run started with",
                                 scene_.file.string()));
  }
  if (state.engine != stepper_->engine()) {
    throw InputError(
        file, fmt::format("written by the {} engine, and this run uses the {} (resume with {}, as the run "
                          "that wrote it)",
                          state.engine, stepper_->engine(), engine_flags(state.engine)));
  }
  if (std::bit_cast<std::uint64_t>(state.dt) != std::bit_cast<std::uint64_t>(result_.dt)) {
    throw InputError(file, fmt::format("written with dt = {:.17g} s, but the scene now gives {:.17g} s",
                                       state.dt, result_.dt));
  }
  check_scene_constants(state.world, initial, file);
  restore(state, file);
  log::info("{}: resuming at step {} (t = {:.6g} s)", file.string(), step_, world_.time);
}

void SceneRun::restore(const RunState& s, const std::filesystem::path& file) {
  world_ = s.world;
  stepper_->load(world_);
  try {
    std::vector<PourEmitter>& pours = drivers_->pours();
    if (s.pours.size() != pours.size()) throw InputError("its pour emitters are not the scene's");
    for (std::size_t i = 0; i < pours.size(); ++i) pours[i].restore(s.pours[i]);
    stepper_->restore_state(world_, s.engine_state);
  } catch (const InputError& e) {
    throw InputError(file, e.what());
  }
  duration_ = control_.duration > 0 ? control_.duration : s.duration;
  output_.emplace(scene_, dir_, hooks_);
  try {
    output_->restore(s.metrics_csv, s.frames);
  } catch (const InputError& e) {
    throw InputError(file, e.what());
  }
  step_ = s.step;
  stretch_end_ = s.stretch_end;
  stretch_output_ = s.stretch_output;
  last_output_step_ = s.last_output_step;
  velocity_clamps_ = s.velocity_clamps;
  angular_clamps_ = s.angular_clamps;
  overlap_clamps_ = s.overlap_clamps;
  overflows_ = s.spring_overflows;
  result_.spring_overflows = s.run_spring_overflows;
  watch_.restore(s.clamp_watch);
  stats_ = s.last;
  result_.resumed_from = s.step;
}

// Releases due grains (after the first step) and updates the servos due, then sets where the stretch
// ends: at the next output, or sooner while pouring or at the next servo update.
void SceneRun::begin_stretch() {
  if (drivers_->act(world_, *stepper_, step_)) stepper_->load(world_);
  const std::int64_t every = scene_.output.every;
  stretch_output_ = std::min(total_, (step_ / every + 1) * every);
  stretch_end_ = std::min(stretch_output_, drivers_->stretch_end(step_));
}

// Where the next advance stops: the stretch's end, or sooner for a checkpoint or a look at the clock.
std::int64_t SceneRun::stop_at() const {
  std::int64_t until = stretch_end_;
  const std::int64_t every = scene_.output.checkpoint_every;
  if (every > 0) until = std::min(until, (step_ / every + 1) * every);
  if (scene_.output.checkpoint_seconds > 0) until = std::min(until, step_ + clock_stretch_);
  return until;
}

void SceneRun::advance_to(std::int64_t until) {
  last_good_ = world_;
  const auto start = Clock::now();
  try {
    stats_ = stepper_->advance(world_, until - step_);
    // The engines check the state each step starts from; the state this stretch ended in (the run's
    // last, at the last stretch) is checked the same way here.
    if (scene_.simulation.step.check_penetration) {
      if (const Penetration p = find_wall_penetration(world_); p.count > 0)
        throw WallPenetration(world_.time, p);
    }
  } catch (const WallPenetration& e) {
    write_particles_ply(last_good_, dir_ / "last_good.ply");
    throw Error(ExitCode::Unstable, describe_penetration(e, world_, sources_));
  } catch (const Error& e) {
    if (e.code() == ExitCode::Unstable) write_particles_ply(last_good_, dir_ / "last_good.ply");
    throw;
  }
  // About four looks at the clock per checkpoint interval, at most one a second.
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const double rate = static_cast<double>(until - step_) / std::max(seconds, 1e-6);  // steps/s
  clock_stretch_ =
      std::max<std::int64_t>(1, std::llround(rate * std::min(1.0, scene_.output.checkpoint_seconds / 4)));
  step_ = until;
  velocity_clamps_ += stats_.velocity_clamps;
  angular_clamps_ += stats_.angular_velocity_clamps;
  overlap_clamps_ += stats_.overlap_clamps;
  overflows_ += stats_.spring_overflows;
  result_.spring_overflows += stats_.spring_overflows;
}

// At an output step: the row and files of the output, then the clamp watch over its interval.
void SceneRun::end_stretch() {
  if (step_ != stretch_output_) return;
  stats_.spring_overflows = std::exchange(overflows_, 0);
  stats_.velocity_clamps = std::exchange(velocity_clamps_, 0);
  stats_.angular_velocity_clamps = std::exchange(angular_clamps_, 0);
  stats_.overlap_clamps = std::exchange(overlap_clamps_, 0);
  output_->write(world_, stats_, step_, *stepper_);
  if (!drivers_->servos().empty()) write_file_atomically(dir_ / "servo.csv", drivers_->servos().csv());  // whole, as metrics.csv
  try {
    watch_.interval(stats_.velocity_clamps + stats_.angular_velocity_clamps, step_ - last_output_step_,
                    world_.time);
  } catch (const Error&) {
    write_particles_ply(last_good_, dir_ / "last_good.ply");
    throw;
  }
  last_output_step_ = step_;
}

void SceneRun::checkpoint_if_due() {
  if (!checkpointing()) return;
  const std::int64_t every = scene_.output.checkpoint_every;
  const double seconds = scene_.output.checkpoint_seconds;
  const bool by_steps = every > 0 && step_ % every == 0;
  const bool by_clock =
      seconds > 0 && std::chrono::duration<double>(Clock::now() - last_checkpoint_).count() >= seconds;
  if (!by_steps && !by_clock && step_ < total_)
    return;  // the last step always gets one: a run can be extended
  write_checkpoint(dir_, state());
  last_checkpoint_ = Clock::now();
  ++result_.checkpoints;
  if (hooks_.on_checkpoint) hooks_.on_checkpoint(checkpoint_path(dir_, step_), step_);
}

RunState SceneRun::state() const {
  RunState s;
  s.scene_hash = hash_;
  s.engine = stepper_->engine();
  s.duration = duration_;
  s.dt = result_.dt;
  s.step = step_;
  s.stretch_end = stretch_end_;
  s.stretch_output = stretch_output_;
  s.frames = output_->count();
  s.last_output_step = last_output_step_;
  s.velocity_clamps = velocity_clamps_;
  s.angular_clamps = angular_clamps_;
  s.overlap_clamps = overlap_clamps_;
  s.spring_overflows = overflows_;
  s.run_spring_overflows = result_.spring_overflows;
  s.clamp_watch = watch_.state();
  s.last = stats_;
  for (const PourEmitter& p : drivers_->pours()) s.pours.push_back(p.progress());
  s.metrics_csv = output_->csv();
  s.world = world_;
  s.engine_state = stepper_->save_state();
  return s;
}

RunResult SceneRun::run() {
  control_.resume ? resume() : start_fresh();
  total_ =
      checked_step_count(duration_, result_.dt,
                         Where{scene_.file.string(), line_of_key(scene_, "simulation.dt"), "simulation.dt"});
  if (stretch_end_ > total_)
    stretch_end_ = stretch_output_ = std::max(step_, total_);  // a shorter --duration
  while (step_ < total_) {
    if (step_ == stretch_end_) begin_stretch();
    advance_to(stop_at());
    if (step_ == stretch_end_) end_stretch();
    checkpoint_if_due();
  }
  result_.steps = step_;
  result_.last = stats_;
  result_.bodies = count_bodies(scene_, world_);
  result_.grains = result_.bodies.grains;
  result_.outputs = output_->count();
  result_.files = output_->files();
  if (scene_.has_bonds()) {
    // The counts and the fragment mass distribution at the end (docs/validation.md, criterion 5), from
    // one search for the fragments.
    const Fragments f = find_fragments(world_, prop_body_ranges(scene_, world_));
    result_.bonds = count_bonds(world_, f);
    write_file_atomically(dir_ / "fragments.csv", fragments_csv(f));
    result_.files.push_back({"fragments.csv", static_cast<std::int64_t>(f.pieces.size()), "rows"});
  }
  if (!drivers_->servos().empty() && output_->count() > 0)
    result_.files.push_back({"servo.csv", drivers_->servos().rows(), "rows"});
  if (hooks_.on_finish) hooks_.on_finish(*stepper_);
  return result_;
}

}  // namespace

BondCounts count_bonds(const World& world, const Fragments& fragments) {
  BondCounts c;
  c.intact = world.bonds.intact_count();
  c.broken = world.bonds.size() - c.intact;
  c.fragments = fragments.count;
  c.largest_fragment_mass = fragments.largest_mass;
  return c;
}

BondCounts count_bonds(const Scene& scene, const World& world) {
  if (!scene.has_bonds()) return {};
  return count_bonds(world, find_fragments(world, prop_body_ranges(scene, world)));
}

BodyCounts count_bodies(const Scene& scene, const World& world) {
  BodyCounts c;
  c.grains = grains_of(scene, world);
  c.dynamic_props = props_moving(scene, MotionType::Dynamic);
  c.kinematic_props = props_moving(scene, MotionType::Kinematic);
  c.static_props = props_moving(scene, MotionType::Static);
  c.rough_walls = bodies_moving(world, MotionType::Static) - c.static_props;
  c.smooth_planes = world.walls.planes.size();
  c.smooth_cylinders = world.walls.cylinders.size();
  return c;
}

RunResult run_scene(const Scene& scene, const std::filesystem::path& output_dir, const RunHooks& hooks,
                    const StepperFactory& make_stepper, const RunControl& control) {
  return SceneRun(scene, output_dir, hooks, make_stepper, control).run();
}

}  // namespace ts::scene
