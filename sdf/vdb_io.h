#pragma once
// OpenVDB files: level sets written atomically, read back with clear errors.
#include <openvdb/openvdb.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "sdf/openvdb_init.h"

namespace ts::sdf {

// Writes `grid` (a float level set named "surface") with string metadata, atomically; refuses to
// overwrite any of `inputs`.
void write_vdb(const std::filesystem::path& path, const openvdb::FloatGrid::Ptr& grid,
               const std::map<std::string, std::string>& metadata = {},
               const std::vector<std::filesystem::path>& inputs = {});

// The first float level-set grid of an OpenVDB file (.vdb), or the grid of a NanoVDB file (.nvdb, told
// by its first bytes), as an OpenVDB grid. ts::InputError for: a missing file, a file that is not
// a VDB, no float grid, a grid that is not a level set, an empty grid, and a file that crashes
// OpenVDB's reader: the file is read in a forked child process (OpenVDB 10 writes past its buffers
// on some broken files), which streams the float grids back. Call it while no other thread holds a
// lock the child would need (OpenVDB's grid registry, the log): fork copies only this thread.
openvdb::FloatGrid::Ptr read_level_set(const std::filesystem::path& path);

namespace detail {
// What to do with a file whose layout check (sdf/vdb_layout.h) stopped at a grid type it does not
// know (bool, mask, points): read it with OpenVDB all the same, or refuse it.
enum class UncheckedGrids { Read, Refuse };

// What read_level_set's child process runs: the file's layout checked (check_vdb_layout), then
// every grid read by OpenVDB in the calling process (with the allocation cap and the stream that
// stops at the file's end); InputError for a file the check or OpenVDB refuses. With
// UncheckedGrids::Read, not safe on files you do not trust: grids the check could not walk reach
// OpenVDB unchecked. fuzz_vdb, which needs the reader's coverage in its own process, refuses them.
openvdb::GridPtrVecPtr read_grids_in_this_process(const std::filesystem::path& path,
                                                  UncheckedGrids unchecked = UncheckedGrids::Read);

// The same for a NanoVDB file: its first grid read (no allocation far above the file's size), checked
// by NanoVDB's validator, converted to OpenVDB. Run in the reader's child process: the conversion follows
// the node offsets the file holds.
openvdb::GridPtrVecPtr read_nanovdb_grid_in_this_process(const std::filesystem::path& path);
}  // namespace detail

}  // namespace ts::sdf
