// tetrasand.run_scene() and tetrasand.Scene: a scene file (or its TOML text) run to the end as
// `tetrasand sim` runs it, or stepped from Python with the state handed out as numpy arrays.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/error.h"
#include "preview/sim_frames.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "scene/scene.h"
#include "scene/scene_checks.h"
#include "scene/scene_drivers.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"

namespace ts::python {

namespace {

// A path (os.PathLike, or a str without a newline or '=') is read as a file; other text is the TOML
// itself, named "<string>" in messages (its relative paths are relative to the working directory).
scene::Scene scene_from(const py::object& source) {
  if (!py::isinstance<py::str>(source)) {
    return scene::load_scene(py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>());
  }
  const std::string text = source.cast<std::string>();
  if (text.find('\n') == std::string::npos && text.find('=') == std::string::npos) return scene::load_scene(text);
  return scene::parse_scene(text, "<string>");
}

sim::Precision precision_from(const std::string& text) {
  if (text == "float") return sim::Precision::Float;
  if (text == "double") return sim::Precision::Double;
  throw py::value_error("precision='" + text + "': must be float or double");
}

// The engine by gpu/backend.h's rule: the GPU pipeline (in `precision`) or the CPU reference.
std::unique_ptr<sim::Stepper> make_stepper(gpu::Context* context, gpu::Backend chosen, const sim::StepSettings& settings,
                                           sim::Precision precision) {
  if (chosen == gpu::Backend::Gpu) return std::make_unique<sim::GpuStepper>(*context, settings, precision);
  return std::make_unique<sim::CpuStepper>(settings);
}

// A scene stepped from Python: the world `tetrasand sim` starts from, the same time step, checks,
// engine, pour emitters and servos; outputs are not written (run_scene writes them).
class SteppedScene {
 public:
  SteppedScene(const py::object& source, const std::string& backend, const std::string& precision)
      : scene_(scene_from(source)) {
    const gpu::Backend requested = backend_from(backend, "backend");
    const sim::Precision bits = precision_from(precision);
    py::gil_scoped_release released;
    context_ = context_for({requested});
    const gpu::Backend chosen = gpu::resolve_backend(requested, context_.get());
    world_ = scene::make_world(scene_, &sources_);
    dt_ = scene::resolve_time_step(scene_, world_, &warning_);
    scene::check_scene_forces(scene_, world_, sources_, dt_);
    sim::StepSettings settings = scene_.simulation.step;
    settings.dt = dt_;
    settings.design_speed = scene::scene_design_speed(scene_, world_).speed;
    stepper_ = make_stepper(context_.get(), chosen, settings, bits);
    drivers_.emplace(scene_, sources_, dt_);
    drivers_->emit(world_);
    stepper_->load(world_);
  }

  // Advances `steps` steps of dt; pour emitters release and servos update where the runner would.
  py::dict step(std::int64_t steps) {
    if (steps < 0) throw py::value_error("steps must be >= 0");
    {
      py::gil_scoped_release released;
      for (std::int64_t left = steps; left > 0;) left -= stretch(left);
    }
    py::dict d;
    d["time"] = world_.time, d["contacts"] = stats_.contacts, d["wall_contacts"] = stats_.wall_contacts;
    d["kinetic_translational_J"] = stats_.energy.translational;
    d["kinetic_rotational_J"] = stats_.energy.rotational, d["potential_J"] = stats_.energy.potential;
    return d;
  }

  const sim::World& world() const { return world_; }
  double dt() const { return dt_; }
  std::int64_t steps() const { return step_; }
  std::string engine() const { return stepper_->engine(); }
  const std::string& time_step_warning() const { return warning_; }

 private:
  // At most `left` steps, up to where the runner's stretch ends (emitters and servos act at stretch
  // ends, whatever chunks Python asks for); returns the steps taken.
  std::int64_t stretch(std::int64_t left) {
    if (step_ == stretch_end_) {
      if (drivers_->act(world_, *stepper_, step_)) stepper_->load(world_);
      stretch_end_ = drivers_->stretch_end(step_);
    }
    const std::int64_t chunk = std::min(left, stretch_end_ - step_);
    stats_ = stepper_->advance(world_, chunk);
    step_ += chunk;
    return chunk;
  }

  scene::Scene scene_;
  std::unique_ptr<gpu::Context> context_;  // before the stepper: the GPU pipeline's buffers live in it
  sim::World world_;
  scene::WorldSources sources_;
  std::unique_ptr<sim::Stepper> stepper_;
  std::optional<scene::SceneDrivers> drivers_;  // the pour emitters and the props' servos
  std::int64_t step_ = 0, stretch_end_ = 0;
  double dt_ = 0;
  std::string warning_;
  sim::StepStats stats_;
};

// Orientations (body -> world) as N x 4 quaternions w, x, y, z (the scene files' order).
py::array_t<double> quaternions(const std::vector<Eigen::Quaterniond>& q) {
  py::array_t<double> out({static_cast<py::ssize_t>(q.size()), py::ssize_t{4}});
  auto view = out.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < view.shape(0); ++i) {
    const Eigen::Quaterniond& r = q[static_cast<std::size_t>(i)];
    view(i, 0) = r.w(), view(i, 1) = r.x(), view(i, 2) = r.y(), view(i, 3) = r.z();
  }
  return out;
}

template <typename T>
py::array_t<T> column(const std::vector<T>& values) {
  py::array_t<T> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

// What a run to the end reports, as `tetrasand sim --json` names it.
py::dict run_summary(const scene::RunResult& r, const std::string& engine) {
  py::dict d;
  d["engine"] = engine, d["steps"] = r.steps, d["dt_s"] = r.dt, d["grains"] = r.grains, d["outputs"] = r.outputs;
  d["time_step_warning"] = r.time_step_warning.empty() ? py::object(py::none()) : py::str(r.time_step_warning);
  d["spring_overflows"] = r.spring_overflows;
  py::dict files;
  for (const scene::OutputRecord& f : r.files) files[py::str(f.pattern)] = f.count;
  d["files"] = files;
  d["contacts"] = r.last.contacts;
  d["kinetic_translational_J"] = r.last.energy.translational;
  d["potential_J"] = r.last.energy.potential;
  return d;
}

// The run's progress, handed to the Python callable (time [s], step) with the GIL held; the callable
// is held by pointer (see body_binding.cpp's progress_of).
void report_progress(scene::RunHooks& hooks, const py::object& progress) {
  if (progress.is_none()) return;
  const py::object* call = &progress;
  hooks.on_output = [call](const sim::World& world, const sim::StepStats&, std::int64_t step) {
    py::gil_scoped_acquire gil;
    (*call)(world.time, step);
  };
}

py::dict run_to_end(const py::object& source, const std::filesystem::path& output_dir, std::optional<double> duration,
                    const std::string& backend, const std::string& precision, const py::object& progress) {
  if (duration && !(*duration > 0.0)) throw py::value_error("duration must be > 0 (s)");
  const scene::Scene scene = scene_from(source);
  const gpu::Backend requested = backend_from(backend, "backend");
  const sim::Precision bits = precision_from(precision);
  scene::RunHooks hooks;
  report_progress(hooks, progress);
  std::string engine;
  hooks.on_finish = [&engine](sim::Stepper& stepper) { engine = stepper.engine(); };
  py::gil_scoped_release released;
  // The frames' renderer needs a context even where the steps run on the CPU (as `tetrasand sim`).
  const std::unique_ptr<gpu::Context> context = context_for({scene.output.frames ? gpu::Backend::Gpu : requested});
  const gpu::Backend chosen = gpu::resolve_backend(requested, context.get());
  std::unique_ptr<preview::SimFrameWriter> frames;
  if (scene.output.frames) {
    frames = std::make_unique<preview::SimFrameWriter>(*context, scene);
    hooks.write_frame = [&frames](const sim::World& w, std::int64_t frame, const std::filesystem::path& dir) {
      frames->write(w, frame, dir);
    };
  }
  scene::StepperFactory factory = [&](const sim::StepSettings& settings) {
    return make_stepper(context.get(), chosen, settings, bits);
  };
  scene::RunControl control;
  control.duration = duration.value_or(0.0);
  const scene::RunResult result = scene::run_scene(scene, output_dir, hooks, factory, control);
  py::gil_scoped_acquire gil;
  return run_summary(result, engine);
}

void add_scene_class(py::module_& m) {
  py::class_<SteppedScene>(m, "Scene", "A scene (file path or TOML text) stepped from Python")
      .def(py::init<const py::object&, const std::string&, const std::string&>(), py::arg("scene"), py::kw_only(),
           py::arg("backend") = "auto", py::arg("precision") = "float")
      .def("step", &SteppedScene::step, py::arg("steps") = 1,
           "Advances this many steps of dt; returns the last step's time, contacts and energies")
      .def_property_readonly("dt", &SteppedScene::dt, "time step [s]")
      .def_property_readonly("steps", &SteppedScene::steps)
      .def_property_readonly("time", [](const SteppedScene& s) { return s.world().time; }, "[s]")
      .def_property_readonly("engine", &SteppedScene::engine)
      .def_property_readonly("time_step_warning", &SteppedScene::time_step_warning)
      .def_property_readonly("positions", [](const SteppedScene& s) { return points_array(sim::particle_positions(s.world())); },
                             "P x 3 particle centres [m], world frame")
      .def_property_readonly("radii", [](const SteppedScene& s) { return column(s.world().particles.radius); })
      .def_property_readonly("particle_body", [](const SteppedScene& s) { return column(s.world().particles.body); })
      .def_property_readonly("body_positions", [](const SteppedScene& s) { return points_array(s.world().bodies.position); },
                             "B x 3 centres of mass [m]")
      .def_property_readonly("velocities", [](const SteppedScene& s) { return points_array(s.world().bodies.linear_velocity); },
                             "B x 3 linear velocities [m/s]")
      .def_property_readonly("angular_velocities",
                             [](const SteppedScene& s) { return points_array(s.world().bodies.angular_velocity); },
                             "B x 3 [rad/s], world frame")
      .def_property_readonly("orientations", [](const SteppedScene& s) { return quaternions(s.world().bodies.orientation); },
                             "B x 4 quaternions w, x, y, z (body -> world)");
}

}  // namespace

void add_scene_bindings(py::module_& m) {
  add_scene_class(m);
  m.def("run_scene", &run_to_end, py::arg("scene"), py::arg("output_dir"), py::kw_only(),
        py::arg("duration") = py::none(), py::arg("backend") = "auto", py::arg("precision") = "float",
        py::arg("progress") = py::none(),
        "Runs a scene (file path or TOML text) to the end as `tetrasand sim` does, writing its [output] files "
        "into output_dir; progress(time, step) at each output; returns the run's summary");
}

}  // namespace ts::python
