// The .vdb reader (sdf/vdb_io.h): what `preview` reads as an SDF. read_level_set runs OpenVDB's reader
// in a child process, whose coverage libFuzzer cannot see (and a fork an input cost 38 inputs a
// second under ASan), so this target runs that child's part in its own process: OpenVDB's tree
// readers are header templates, compiled and instrumented here. The upstream heap overflow of
// fuzz/findings/README.md therefore still ends a run here; read_level_set contains it.
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
    (void)ts::sdf::detail::read_grids_in_this_process(file, ts::sdf::detail::UncheckedGrids::Refuse);
  } catch (const ts::InputError&) {
  }
  return 0;
}
