// The body reader (body/body_file.h read_body): NAME.body.json and the NAME.particles.ply it names.
// The input is the JSON, a NUL byte, then the PLY (no NUL: the JSON alone, the PLY empty); the JSON
// is read with both key sets, the PLY also alone (body/particles_ply.h, what preview --particles reads).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "body/body_file.h"
#include "body/particles_ply.h"
#include "core/error.h"
#include "core/log.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ts::log::set_level(ts::log::Level::Error);
  const std::string_view input = ts::fuzz::as_text(data, size);
  const std::size_t nul = input.find('\0');
  const std::string_view json = input.substr(0, nul);
  const std::string_view ply = nul == std::string_view::npos ? std::string_view() : input.substr(nul + 1);
  // The name the bundled bodies' JSON gives its PLY (seeds from assets/bodies/ name cube.particles.ply).
  const auto json_file = ts::fuzz::scratch_file("cube.body.json", json);
  const auto ply_file = ts::fuzz::scratch_file("cube.particles.ply", ply);
  for (const auto keys : {ts::body::BodyKeys::All, ts::body::BodyKeys::Physical}) {
    try {
      (void)ts::body::read_body(json_file, keys);
    } catch (const ts::InputError&) {
    }
  }
  try {
    (void)ts::body::read_particles_ply(ply_file);
  } catch (const ts::InputError&) {
  }
  return 0;
}
