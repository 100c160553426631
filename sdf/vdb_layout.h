#pragma once
// A walk over a .vdb file's layout ahead of OpenVDB's reader. OpenVDB 10 trusts the file: it reads
// an uncompressed chunk into a node's buffer before it compares the chunk's size with the buffer's
// (a heap overflow, fuzz/findings/README.md), hands blosc a compressed chunk whose header it never
// compares with the chunk's length, allocates what a length field claims before reading it, and
// loops over counts without looking at the stream's end. This walk follows the reader's own order
// (OpenVDB 10's io::Stream: header, metadata, grid descriptors, transforms, tree topology, leaf
// buffers) and compares every length, count and chunk header with the bytes the file holds and the
// buffer the reader will fill. A file it passes holds none of those faults; it reads nothing into
// memory but masks and headers.
#include <cstdint>
#include <filesystem>
#include <string>

namespace ts::sdf {

struct VdbLayout {
  std::uint32_t file_version = 0;
  int grid_count = 0;
  // Empty when every grid was walked. Otherwise the first grid whose tree this walk does not know
  // (bool, mask, point and custom trees: "grid 'NAME' of type T"); neither it nor the grids after
  // it were checked, since their layout decides where the next grid starts.
  std::string unchecked;

  bool complete() const { return unchecked.empty(); }
};

// Walks `path` as OpenVDB 10's stream reader would. Throws ts::InputError naming the file, the byte
// offset and what is wrong for a file the reader would overrun, over-allocate for or fail on
// midway (a length past the file's end, a chunk that does not match its node, an unregistered grid,
// transform or metadata type, a file format version other than 222-224).
VdbLayout check_vdb_layout(const std::filesystem::path& path);

}  // namespace ts::sdf
