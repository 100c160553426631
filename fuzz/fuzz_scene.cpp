// The scene parser (scene/scene.h parse_scene: the TOML, every key and its checks), as if the text were
// a scene in assets/scenes/ (relative paths resolve as for the bundled scenes). The bodies a scene
// names are read later, by the world's builder, through read_body: fuzz_body covers that reader.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/log.h"
#include "fuzz/fuzz_support.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ts::log::set_level(ts::log::Level::Error);
  static const std::filesystem::path kScene =
      std::filesystem::path(TETRASAND_SOURCE_DIR) / "assets/scenes/fuzzed.toml";
  try {
    (void)ts::scene::parse_scene(ts::fuzz::as_text(data, size), kScene);
  } catch (const ts::InputError&) {
  }
  return 0;
}
