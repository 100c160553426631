#include "sdf/vdb_io.h"

#include <mutex>

#include "core/atomic_file.h"
#include "core/error.h"

namespace ts::sdf {

void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

void write_vdb(const std::filesystem::path& path, const openvdb::FloatGrid::Ptr& grid,
               const std::map<std::string, std::string>& metadata, const std::vector<std::filesystem::path>& inputs) {
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
  try {
    openvdb::io::File file(path.string());
    file.open();
    grids = file.getGrids();
    file.close();
  } catch (const openvdb::Exception& e) {
    throw InputError(path, std::string("is not a readable OpenVDB file (") + e.what() + ")");
  }
  bool any_float = false;
  for (const auto& base : *grids) {
    auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) continue;
    any_float = true;
    if (grid->getGridClass() != openvdb::GRID_LEVEL_SET) continue;
    if (grid->activeVoxelCount() == 0) throw InputError(path, "its level set '" + grid->getName() + "' is empty");
    return grid;
  }
  throw InputError(path, any_float ? "holds float grids but none is a level set (class fog volume or unknown)"
                                   : "holds no float grid (a level set is a float grid)");
}

}  // namespace ts::sdf
