// The scene parser (scene/scene.h parse_scene: the TOML, every key and its checks), as if the text were
// a scene in assets/scenes/ (relative paths resolve as for the bundled scenes), and then, for a scene
// small enough to step in milliseconds (at most kMostParticles particles from its emitters and rough
// boundaries), a short run on the CPU reference: an exit-0 run must hold only finite numbers, in its
// state and in the files it wrote, with every particle within the grid's documented reach
// (fuzz/run_checks.h). The bodies a scene names are read by the world's builder through read_body:
// fuzz_body covers that reader on its own.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/log.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/run_checks.h"
#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace {
constexpr double kMostParticles = 400;
constexpr std::int64_t kMaxSteps = 100;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ts::log::set_level(ts::log::Level::Error);
  static const std::filesystem::path kScene =
      std::filesystem::path(TETRASAND_SOURCE_DIR) / "assets/scenes/fuzzed.toml";
  ts::scene::Scene scene;
  try {
    scene = ts::scene::parse_scene(ts::fuzz::as_text(data, size), kScene);
    ts::scene::check_scene_sizes(scene);
  } catch (const ts::InputError&) {
    return 0;
  }
  if (!(ts::scene::implied_particles(scene) <= kMostParticles)) return 0;
  scene.output.frames = false;  // the preview renderer is not linked here (and is no reader)
  // A checkpoint hashes the scene file, which a fuzzed text does not have: fuzz_checkpoint covers them.
  scene.output.checkpoint_every = 0;
  scene.output.checkpoint_seconds = 0;
  ts::fuzz::run_and_check(scene, ts::fuzz::scratch_dir() / "scene_run", {}, kMaxSteps);
  return 0;
}
