#pragma once
// Input files are read only when they are regular files of a size their format can need (issue 46):
// `/dev/zero` given as a body or a scene was read whole into memory (6-8 GB before it was stopped),
// a FIFO blocked forever, and assimp and OpenVDB open whatever name they are given. A FIFO, a device,
// a socket or a directory is refused at once, naming it, without opening it for reading.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>

namespace ts {

inline constexpr std::uint64_t kNoSizeBound = std::numeric_limits<std::uint64_t>::max();

// Throws InputError naming `path` unless it is (or links to) a regular file: "no such file", "is a
// directory, not a file", "is a FIFO (named pipe), not a regular file", "is a character device ...".
// Returns its size in bytes.
std::uint64_t require_regular_file(const std::filesystem::path& path);

// The whole of the regular file `path`, refused (InputError naming it and the bound) when it holds more
// than `max_bytes`; `why` says where the bound comes from ("a scene is a text of keys"). The file is
// opened without blocking and checked again once open, so a FIFO put in its place meanwhile is refused
// too; at most its size at that moment is read.
std::string read_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes = kNoSizeBound,
                              std::string_view why = {});

}  // namespace ts
