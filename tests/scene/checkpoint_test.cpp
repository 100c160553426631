// Checkpoints (scene/checkpoint.h): a run stopped at a checkpoint, or after one, and resumed writes the
// same bytes as the run that never stopped, on the CPU reference and on the GPU pipeline; a
// missing, damaged or mismatched checkpoint is refused naming the file.
#include "scene/checkpoint.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "gpu/context.h"
#include "sim/gpu_stepper.h"
#include "scene/scene_runner.h"
#include "scene/scene_world.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

namespace ts::scene {
namespace {

namespace fs = std::filesystem;

// Everything a checkpoint must carry at once: grains poured as the run goes (the emitter's site and
// generator), a fill, tangential springs, a keyframed kinematic plate, a rough floor and smooth walls.
// Checkpoints every 37 steps fall inside the stretches between pour releases (36 steps) and outputs
// (100 steps).
std::string scene_text(const std::string& engine_keys, const std::string& pour_size = "") {
  test::PouredScene p;
  p.pour_extra = "velocity = [0.0, 0.0, -0.5]\n" + pour_size;
  p.boundaries = R"([[boundary]]
type = "plane"
rough = true
point = [0.0, 0.0, 0.0]
size = [0.1, 0.1]
particle_radius = 5.0e-3
material = "sand"
)" + test::smooth_plane("[0.05, 0.0, 0.0]", "[-1.0, 0.0, 0.0]") +
                 R"([[boundary]]
type = "cylinder"
radius = 0.07
z_min = 0.0
z_max = 0.2
material = "sand"
)";
  p.simulation = engine_keys;
  // With the .vtp files, whose .pvd collection a resumed run must take up where the stopped one left it.
  std::string text = test::poured_scene(p);
  const std::size_t ply = text.find("ply = true\n");
  return ply == std::string::npos ? text : text.insert(ply, "vtp = true\n");
}

Scene write_scene(const fs::path& dir, const std::string& engine_keys = "",
                  const std::string& pour_size = "") {
  write_file_atomically(dir / "scene.toml", scene_text(engine_keys, pour_size));
  return load_scene(dir / "scene.toml");
}

struct Stop {};  // thrown from a hook: the run ends there, as if killed

// The files of a run's folder that a run writes as outputs (not its checkpoints), by name.
std::map<std::string, std::string> outputs(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.ends_with(".tsck")) continue;
    files[name] = read_file(e.path());
  }
  return files;
}

// Runs `scene` to the end in `dir`; returns the final world's bytes.
std::string run_through(const Scene& scene, const fs::path& dir, const StepperFactory& factory,
                        const RunControl& control = {}) {
  World last;
  RunHooks hooks;
  hooks.on_output = [&](const World& w, const StepStats&, std::int64_t) { last = w; };
  run_scene(scene, dir, hooks, factory, control);
  return world_bytes(last);
}

// Stops a run at its `n`th checkpoint (or, with `after_output`, at the first output after it), then
// resumes it, possibly several times; the outputs and the final state must be the uninterrupted run's.
void expect_resume_is_bitwise(const Scene& scene, const StepperFactory& factory, const fs::path& dir) {
  Scene plain = scene;
  plain.output.checkpoint_every = 0;
  plain.output.checkpoint_seconds = 0;
  const std::string expected = run_through(plain, dir / "plain", factory);
  const auto expected_files = outputs(dir / "plain");
  ASSERT_GE(expected_files.size(), 4u);
  for (const auto& [n, after_output] : {std::pair{1, false}, std::pair{3, true}, std::pair{5, false}}) {
    const fs::path out = dir / fmt::format("stopped_{}_{}", n, after_output);
    int checkpoints = 0;
    bool stop_next_output = false;
    RunHooks stopping;
    stopping.on_checkpoint = [&](const fs::path&, std::int64_t) {
      if (++checkpoints == n && !after_output) throw Stop{};
      stop_next_output = stop_next_output || checkpoints == n;
    };
    stopping.on_output = [&](const World&, const StepStats&, std::int64_t) {
      if (stop_next_output) throw Stop{};
    };
    EXPECT_THROW(run_scene(scene, out, stopping, factory), Stop);
    RunControl resume;
    resume.resume = true;
    EXPECT_EQ(run_through(scene, out, factory, resume), expected) << out;
    EXPECT_EQ(outputs(out), expected_files) << out;
  }
}

TEST(Checkpoint, ResumedCpuRunIsBitwiseTheUninterruptedOne) {
  const fs::path dir = test::temp_dir();
  expect_resume_is_bitwise(write_scene(dir), {}, dir);
}

// Bonds (issue 48): the scrape scene with its tool already at the layer, so bonds break within the
// short run; the bonds' loads, strengths and broken flags are in the checkpoint, and a resumed run
// breaks the same bonds in the same steps.
TEST(Checkpoint, ResumedRunWithBreakingBondsIsBitwiseTheUninterruptedOne) {
  const fs::path dir = test::temp_dir();
  Scene scene = load_scene(test::asset("scenes/scrape.toml"));
  for (Keyframe& k : scene.props.at(2).keyframes) k.position.x() += 0.008;  // m: touching at t = 0
  scene.simulation.duration = 0.003;
  scene.output.every = 250;
  scene.output.ply = true;
  scene.output.checkpoint_every = 180;
  expect_resume_is_bitwise(scene, {}, dir);
  const std::string csv = read_file(dir / "plain" / "metrics.csv");
  const std::string last = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
  std::vector<std::string> fields;
  for (std::size_t at = 0, comma; at <= last.size(); at = comma + 1) {
    comma = std::min(last.find(',', at), last.size());
    fields.push_back(last.substr(at, comma - at));
  }
  ASSERT_EQ(fields.size(), 18u);
  EXPECT_GT(std::stoi(fields[15]), 0) << "no bond broke: " << last;  // bonds_broken
}

// Poured grains of varying size (issue 18): each has its own mass and inertia, which the checkpoint
// keeps with the bodies; the emitter's sizes still to come follow from its seed and release count.
TEST(Checkpoint, ResumedPolydispersePourIsBitwiseTheUninterruptedOne) {
  const fs::path dir = test::temp_dir();
  const Scene scene = write_scene(dir, "", "size = { distribution = \"uniform\", min = 0.7, max = 1.0 }\n");
  expect_resume_is_bitwise(scene, {}, dir);
}

TEST(Checkpoint, ResumedGpuRunIsBitwiseTheUninterruptedOneAcrossResorts) {
  gpu::Context context;
  const fs::path dir = test::temp_dir();
  // Re-sorts every 13 steps: the GPU memory order and its step counter are state a checkpoint keeps.
  const Scene scene = write_scene(dir, "resort_every = 13");
  expect_resume_is_bitwise(
      scene, [&](const StepSettings& s) { return std::make_unique<GpuStepper>(context, s); }, dir);
}

TEST(Checkpoint, CheckpointsByWallClockSplitStretchesWithoutChangingABit) {
  const fs::path dir = test::temp_dir();
  Scene scene = write_scene(dir);
  scene.output.checkpoint_every = 0;
  scene.output.checkpoint_seconds = 1e-3;  // s: many per run, at steps the clock picks
  const RunResult result = run_scene(scene, dir / "clock");
  EXPECT_GT(result.checkpoints, 5);
  expect_resume_is_bitwise(scene, {}, dir);
}

// The runs above end the same whatever the engine state in this small scene (found: they pass with
// restore_state skipped), so the engine's own state is checked directly: a GPU pipeline given the
// downloaded world and the saved state is the saved pipeline, byte for byte, memory order after a
// re-sort included, and steps on as it does.
TEST(Checkpoint, RestoredGpuPipelineIsTheSavedOneAfterAResort) {
  gpu::Context context;
  const fs::path dir = test::temp_dir();
  const Scene scene = write_scene(dir);
  World world = make_world(scene);
  StepSettings settings = scene.simulation.step;
  settings.dt = resolve_time_step(scene, world, nullptr);
  settings.resort_every = 13;
  GpuStepper saved(context, settings);
  saved.load(world);
  saved.advance(world, 20);  // re-sorted at step 13
  const std::string state = saved.save_state();
  GpuStepper fresh(context, settings);
  fresh.load(world);
  EXPECT_NE(fresh.save_state(), state);  // world order, no steps since a re-sort: not the same pipeline
  GpuStepper restored(context, settings);
  World copy = world;
  restored.load(copy);
  restored.restore_state(copy, state);
  EXPECT_EQ(restored.save_state(), state);
  saved.advance(world, 30);  // past the next re-sort
  restored.advance(copy, 30);
  EXPECT_EQ(world_bytes(copy), world_bytes(world));
  EXPECT_EQ(restored.save_state(), saved.save_state());
}

TEST(Checkpoint, StateRoundTripsByteForByteAndOnlyTheTwoLatestAreKept) {
  const fs::path dir = test::temp_dir();
  const Scene scene = write_scene(dir);
  run_scene(scene, dir / "out");
  fs::path file;
  const RunState state = read_latest_checkpoint(dir / "out", &file);
  EXPECT_EQ(state.step, state.stretch_end);  // the last step of the run always gets a checkpoint
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir / "out")) files += e.path().extension() == ".tsck" ? 1 : 0;
  EXPECT_EQ(files, 2u);
  write_checkpoint(dir / "copy", state);
  EXPECT_EQ(read_file(checkpoint_path(dir / "copy", state.step)), read_file(file));
  // A fresh run in the folder removes the old run's checkpoints with its other outputs.
  Scene plain = scene;
  plain.output.checkpoint_every = 0;
  run_scene(plain, dir / "out");
  EXPECT_THROW(read_latest_checkpoint(dir / "out"), InputError);
}

// The InputError message of resuming `scene` from `dir`.
std::string resume_error(const Scene& scene, const fs::path& dir, const StepperFactory& factory = {}) {
  RunControl resume;
  resume.resume = true;
  try {
    run_scene(scene, dir, {}, factory, resume);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Checkpoint, MissingCorruptAndMismatchedCheckpointsAreRefusedNamingTheFile) {
  const fs::path dir = test::temp_dir();
  const Scene scene = write_scene(dir);
  EXPECT_NE(resume_error(scene, dir / "nowhere").find("no such folder to resume from"), std::string::npos);
  fs::create_directories(dir / "empty");
  EXPECT_NE(resume_error(scene, dir / "empty").find("no checkpoint to resume from"), std::string::npos);

  Scene short_run = scene;
  short_run.simulation.duration = 0.01;
  run_scene(short_run, dir / "out");
  fs::path file;
  read_latest_checkpoint(dir / "out", &file);
  const std::string good = read_file(file);
  auto refused_with = [&](const std::string& bytes, const std::string& problem) {
    write_file_atomically(file, bytes);
    const std::string message = resume_error(scene, dir / "out");
    EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  };
  refused_with(good.substr(0, good.size() / 2), "corrupt");
  std::string flipped = good;
  flipped[flipped.size() / 3] ^= 0x10;
  refused_with(flipped, "corrupt");
  std::string version = good;
  version[8] = static_cast<char>(kCheckpointVersion + 1);  // the version follows the 8-byte magic
  refused_with(version, fmt::format("checkpoint format version {}", kCheckpointVersion + 1));
  refused_with("hello", "not a tetrasand checkpoint");

  write_file_atomically(file, good);
  std::string text = read_file(dir / "scene.toml");
  text.replace(text.find("mu = 0.5"), 8, "mu = 0.4");
  write_file_atomically(dir / "changed.toml", text);
  EXPECT_NE(resume_error(load_scene(dir / "changed.toml"), dir / "out").find("written for another scene"),
            std::string::npos);
  gpu::Context context;
  const std::string engine = resume_error(
      scene, dir / "out", [&](const StepSettings& s) { return std::make_unique<GpuStepper>(context, s); });
  EXPECT_NE(engine.find("written by the cpu reference engine, and this run uses the gpu float"),
            std::string::npos)
      << engine;
  EXPECT_EQ(resume_error(scene, dir / "out"), "");  // the good one still resumes
}

// A checkpoint crafted with values a fresh scene could never have, its checksum recomputed (written
// through write_checkpoint), is refused naming the field: it would resume into NaN outputs.
TEST(Checkpoint, CraftedCheckpointsWithNonFiniteOrMeaninglessValuesAreRefusedNamingTheField) {
  const fs::path dir = test::temp_dir();
  Scene scene = write_scene(dir);
  scene.simulation.duration = 0.01;
  run_scene(scene, dir / "out");
  const RunState good = read_latest_checkpoint(dir / "out");
  std::size_t dynamic = 0;
  while (good.world.bodies.motion.at(dynamic) != MotionType::Dynamic) ++dynamic;
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  const std::vector<std::pair<std::string, std::function<void(RunState&)>>> crafted{
      {"gravity is not finite", [&](RunState& s) { s.world.gravity.z() = inf; }},
      {"time is nan", [&](RunState& s) { s.world.time = nan; }},
      {"body inverse_mass (dynamic)", [&](RunState& s) { s.world.bodies.inverse_mass[dynamic] = 0; }},
      {"particle radius of entry 0 is inf", [&](RunState& s) { s.world.particles.radius[0] = inf; }},
      {"particle radius of entry 0 is -0.001", [&](RunState& s) { s.world.particles.radius[0] = -1e-3; }},
      {"body position of entry 1 is not finite", [&](RunState& s) { s.world.bodies.position[1].x() = nan; }},
      {"body linear_velocity", [&](RunState& s) { s.world.bodies.linear_velocity[dynamic].y() = -inf; }},
      {"body orientation of entry 0: quaternion",
       [&](RunState& s) { s.world.bodies.orientation[0].coeffs().setConstant(1e200); }},
      {"dt must be finite and > 0 (got inf)", [&](RunState& s) { s.dt = inf; }},
      {"the duration must be finite and > 0", [&](RunState& s) { s.duration = nan; }},
      // Found by fuzz_checkpoint: finite, but beyond what a scene could give.
      {"particle position of entry 0 lies 1e+38 grid cells",
       [&](RunState& s) {
         s.world.bodies.position[s.world.particles.body[0]].x() = 1e38 * 2 * s.world.particles.radius[0];
       }},
      {"faster than light", [&](RunState& s) { s.world.bodies.linear_velocity[dynamic].x() = 1e300; }},
      // Found by fuzz_checkpoint: a finite inverse inertia whose inverse is not, which resumed to exit 0
      // with a NaN rotational energy.
      {"body inverse_inertia of entry",
       [&](RunState& s) { s.world.bodies.inverse_inertia[dynamic](1, 1) = 1e308; }},
      {"not positive definite", [&](RunState& s) { s.world.bodies.inverse_inertia[dynamic](2, 2) = -1.0; }},
      {"not symmetric", [&](RunState& s) { s.world.bodies.inverse_inertia[dynamic](0, 1) += 1.0; }},
      {"a mass of 1e-308 kg, outside", [&](RunState& s) { s.world.bodies.inverse_mass[dynamic] = 1e308; }},
  };
  int n = 0;
  for (const auto& [field, craft] : crafted) {
    RunState state = good;
    craft(state);
    const fs::path out = dir / fmt::format("crafted_{}", n++);
    write_checkpoint(out, state);
    std::string message;
    try {
      read_latest_checkpoint(out);
    } catch (const InputError& e) {
      message = e.what();
    }
    EXPECT_NE(message.find(checkpoint_path(out, state.step).string()), std::string::npos)
        << field << ": " << message;
    EXPECT_NE(message.find(field), std::string::npos) << field << ": " << message;
  }
  write_checkpoint(dir / "untouched", good);
  EXPECT_EQ(read_latest_checkpoint(dir / "untouched").step, good.step);  // the good state still reads
}

// What the scene fixes (gravity, smooth walls, materials) and the metrics written so far come back
// only as the scene and the writer would give them: crafted checkpoints with gravity of 1e231 or
// text in metrics.csv resumed to exit 0 (found by fuzz_checkpoint). Refused at resume, naming the
// file and what differs.
TEST(Checkpoint, CraftedSceneConstantsOrMetricsAreRefusedAtResume) {
  const fs::path dir = test::temp_dir();
  Scene scene = write_scene(dir);
  scene.simulation.duration = 0.01;
  run_scene(scene, dir / "out");
  const RunState good = read_latest_checkpoint(dir / "out");
  const std::vector<std::pair<std::string, std::function<void(RunState&)>>> crafted{
      {"its gravity differ from the scene's", [](RunState& s) { s.world.gravity.z() = -1e231; }},
      {"its materials differ from the scene's", [](RunState& s) { s.world.materials.at(0).friction = 5; }},
      {"its smooth walls differ from the scene's", [](RunState& s) { s.world.walls.planes.at(0).point.z() = 1; }},
      {"metrics_csv: row 1 is not 18 finite numbers",
       [](RunState& s) { s.metrics_csv.replace(s.metrics_csv.find('\n') + 1, 1, "x"); }},
      {"metrics_csv: its header is not metrics.csv's", [](RunState& s) { s.metrics_csv[0] = 'S'; }},
  };
  int n = 0;
  for (const auto& [problem, craft] : crafted) {
    RunState state = good;
    craft(state);
    const fs::path out = dir / fmt::format("crafted_{}", n++);
    write_checkpoint(out, state);
    const std::string message = resume_error(scene, out);
    EXPECT_EQ(message.rfind(checkpoint_path(out, state.step).string() + ": ", 0), 0u) << problem << ": " << message;
    EXPECT_NE(message.find(problem), std::string::npos) << problem << ": " << message;
  }
  write_checkpoint(dir / "untouched", good);
  EXPECT_EQ(resume_error(scene, dir / "untouched"), "");  // the good state still resumes
}

}  // namespace
}  // namespace ts::scene
