#pragma once
// OpenVDB's registries of grid, map and metadata types must be filled before any grid is made, read
// or checked; every reader and writer of .vdb files calls this first.
namespace ts::sdf {

// openvdb::initialize(), once per process (thread-safe).
void ensure_openvdb_initialized();

}  // namespace ts::sdf
