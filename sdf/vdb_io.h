#pragma once
// OpenVDB files: level sets written atomically, read back with clear errors.
#include <openvdb/openvdb.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace ts::sdf {

// openvdb::initialize(), once per process.
void ensure_openvdb_initialized();

// Writes `grid` (a float level set named "surface") with string metadata, atomically; refuses to
// overwrite any of `inputs`.
void write_vdb(const std::filesystem::path& path, const openvdb::FloatGrid::Ptr& grid,
               const std::map<std::string, std::string>& metadata = {},
               const std::vector<std::filesystem::path>& inputs = {});

// The first float level-set grid of a file. ts::InputError for: a missing file, a file that is not
// a VDB, no float grid, a grid that is not a level set, an empty grid.
openvdb::FloatGrid::Ptr read_level_set(const std::filesystem::path& path);

}  // namespace ts::sdf
