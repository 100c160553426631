// The .vdb reader (sdf/vdb_io.h read_level_set): what `preview` reads as an SDF.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/log.h"
#include "fuzz/fuzz_support.h"
#include "sdf/vdb_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ts::log::set_level(ts::log::Level::Error);
  const auto file = ts::fuzz::scratch_file("field.vdb", ts::fuzz::as_text(data, size));
  try {
    (void)ts::sdf::read_level_set(file);
  } catch (const ts::InputError&) {
  }
  return 0;
}
