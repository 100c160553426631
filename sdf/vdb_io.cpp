#include "sdf/vdb_io.h"

#include <fmt/format.h>
#include <openvdb/io/Stream.h>

#include <fstream>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>

#include "core/allocation_cap.h"
#include "core/atomic_file.h"
#include "core/error.h"

namespace ts::sdf {
namespace {

// OpenVDB's message about a broken file, fit for one line: it quotes what it read (a type name of
// 64 kB from a fuzzed file), so it is cut at 200 characters and its control bytes escaped.
std::string openvdb_problem(const std::string& message) {
  constexpr std::size_t kMost = 200;
  std::string out;
  for (const char c : message.substr(0, kMost)) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte < 0x20 || byte >= 0x7f ? fmt::format("\\x{:02x}", byte) : std::string(1, c);
  }
  if (message.size() > kMost) out += fmt::format("... ({} characters)", message.size());
  return out;
}

}  // namespace

void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

void write_vdb(const std::filesystem::path& path, const openvdb::FloatGrid::Ptr& grid,
               const std::map<std::string, std::string>& metadata,
               const std::vector<std::filesystem::path>& inputs) {
  ensure_openvdb_initialized();
  for (const auto& [key, value] : metadata) grid->insertMeta(key, openvdb::StringMetadata(value));
  write_atomically(
      path,
      [&](const std::filesystem::path& tmp) {
        try {
          openvdb::io::File file(tmp.string());
          openvdb::GridPtrVec grids{grid};
          file.write(grids);
          file.close();
        } catch (const openvdb::IoError& e) {  // the place is not writable (permission, space)
          throw InputError(path, std::string("cannot write file (") + e.what() + ")");
        }
      },
      inputs);
}

openvdb::FloatGrid::Ptr read_level_set(const std::filesystem::path& path) {
  ensure_openvdb_initialized();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "no such file");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory, not a .vdb file");
  openvdb::GridPtrVecPtr grids;
  // No single allocation of a sound read comes near the file's size; one far above it is a length
  // field the reader trusts (core/allocation_cap.h): refuse it at once instead of reserving it.
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
  const std::size_t cap = static_cast<std::size_t>(ec ? 0 : file_bytes) * 4 + (std::size_t{64} << 20);
  try {
    const AllocationCap allocation_cap(cap);
    // Read through a stream that throws on the first read past its end: OpenVDB's reader does not
    // look at the stream's state inside its loops, so a count in the file of two billion root tiles
    // ran two billion failed reads (fuzz_vdb, 2026-12-04: a 64 kB file took 18 s).
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "cannot be opened for reading (permission?)");
    in.exceptions(std::ios::failbit | std::ios::badbit);
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    grids = stream.getGrids();
  } catch (const std::ios_base::failure&) {
    throw InputError(path, "is not a readable OpenVDB file (it ends before the data it declares: it is cut short "
                           "or a count in it is wrong)");
  } catch (const openvdb::Exception& e) {
    throw InputError(path, "is not a readable OpenVDB file (" + openvdb_problem(e.what()) + ")");
  } catch (const std::bad_alloc&) {  // a length in the file beyond the cap (or beyond memory)
    throw InputError(path, fmt::format("is not a readable OpenVDB file (a length in it asks for more than {} MiB, "
                                       "more than a file of {} bytes can hold)",
                                       cap >> 20, file_bytes));
  } catch (const std::length_error&) {
    throw InputError(path, "is not a readable OpenVDB file (a size in it is beyond any string or array)");
  }
  bool any_float = false;
  for (const auto& base : *grids) {
    auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) continue;
    any_float = true;
    if (grid->getGridClass() != openvdb::GRID_LEVEL_SET) continue;
    if (grid->activeVoxelCount() == 0)
      throw InputError(path, "its level set '" + grid->getName() + "' is empty");
    return grid;
  }
  throw InputError(path, any_float ? "holds float grids but none is a level set (class fog volume or unknown)"
                                   : "holds no float grid (a level set is a float grid)");
}

}  // namespace ts::sdf
