// Resuming from a checkpoint whose values were changed and whose checksum was recomputed (what a
// crafted file can do): the reader and the resume path must refuse every value a fresh scene would
// refuse, and a resume that ends at exit 0 must pass fuzz/run_checks.h (finite state and files,
// particles within the grid's reach).
//
// The base checkpoint is made once per process: a small scene (tetrahedral grains dropped on a plane)
// run with checkpoints. The input is a list of edits to its payload, 3 bytes each: a little-endian
// uint16 byte offset (modulo the payload's length) and a selector: below kValues.size(), the double
// kValues[selector] written there (infinity, NaN, zero, 1e308...: the values crafted checkpoints
// carried); otherwise the byte there is XORed with it. The file is then sealed again (length,
// SHA-256) so that the edits reach the value checks instead of the checksum.
#include <openssl/evp.h>

#include <algorithm>
#include <array>
#include <limits>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/log.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/run_checks.h"
#include "scene/checkpoint.h"
#include "scene/scene.h"
#include "tests/scene_texts.h"

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kHeader = 8 + 16;  // magic, version, flags, payload length
constexpr std::size_t kDigest = 32;

// Coarse 5 mm grains thrown at a floor, with checkpoints every 80 steps of about 200.
std::string base_scene() {
  return std::string(ts::test::kCoarseSand) + ts::test::smooth_plane("[0.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]") +
         ts::test::box_emitter("fill", "[-0.03, -0.03, 0.01]", "[0.03, 0.03, 0.05]", 4,
                               "velocity = [0.0, 0.0, -1.0]\n") +
         "[simulation]\nduration = 0.04\n[output]\nevery = 40\ncheckpoint_every = 80\n";
}

struct Base {
  ts::scene::Scene scene;
  fs::path dir;            // the base run's output folder
  fs::path checkpoint;     // its latest checkpoint
  std::string bytes;       // that checkpoint's bytes
};

const Base& base() {
  static const Base b = [] {
    Base out;
    const fs::path scene_file = ts::fuzz::scratch_file("checkpoint_scene.toml", base_scene());
    out.scene = ts::scene::load_scene(scene_file);
    out.dir = scene_file.parent_path() / "checkpoint_base";
    ts::scene::run_scene(out.scene, out.dir);
    // The earlier of the two checkpoints kept (step 160 of 204), so that a resume has steps left to
    // run; the later one goes, or the resume would start from it.
    std::vector<fs::path> checkpoints;
    for (const auto& entry : fs::directory_iterator(out.dir))
      if (entry.path().extension() == ".tsck") checkpoints.push_back(entry.path());
    std::sort(checkpoints.begin(), checkpoints.end());
    for (std::size_t i = 1; i < checkpoints.size(); ++i) fs::remove(checkpoints[i]);
    out.checkpoint = checkpoints.at(0);
    out.bytes = ts::read_file(out.checkpoint);
    return out;
  }();
  return b;
}

constexpr std::array<double, 12> kValues = {std::numeric_limits<double>::infinity(),
                                            -std::numeric_limits<double>::infinity(),
                                            std::numeric_limits<double>::quiet_NaN(),
                                            0.0,
                                            -0.0,
                                            1e308,
                                            -1e308,
                                            4.9e-324,
                                            -1.0,
                                            1e38,
                                            1e-300,
                                            9.81e6};

void seal(std::string& file) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_Digest(file.data(), file.size() - kDigest, digest, &length, EVP_sha256(), nullptr);
  std::memcpy(file.data() + file.size() - kDigest, digest, kDigest);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ts::log::set_level(ts::log::Level::Error);
  const Base& b = base();
  std::string file = b.bytes;
  const std::size_t payload = file.size() - kHeader - kDigest;
  for (std::size_t at = 0; at + 3 <= size; at += 3) {
    const std::size_t where = kHeader + (data[at] | std::size_t{data[at + 1]} << 8) % payload;
    const std::uint8_t selector = data[at + 2];
    if (selector < kValues.size()) {
      std::memcpy(file.data() + where, &kValues[selector], std::min<std::size_t>(8, kHeader + payload - where));
    } else {
      file[where] = static_cast<char>(file[where] ^ selector);
    }
  }
  seal(file);
  const fs::path run = b.dir.parent_path() / "checkpoint_run";
  std::error_code ec;
  fs::remove_all(run, ec);
  fs::copy(b.dir, run, fs::copy_options::recursive, ec);
  ts::write_file_atomically(run / b.checkpoint.filename(), file);
  // The base scene's duration caps the resumed run (RunControl::duration), so an edited step counter or
  // duration cannot make it long.
  ts::fuzz::run_and_check(b.scene, run, {.resume = true, .duration = b.scene.simulation.duration}, 0);
  return 0;
}
