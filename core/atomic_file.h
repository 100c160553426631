#pragma once
// Outputs are written atomically: to a temporary file beside the target, then renamed over it,
// so an interrupted run never leaves a half-written file and an existing output is replaced whole.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>
#include <vector>

#include "core/input_file.h"

namespace ts {

// Writes a file's bytes into `out`; a failed write need not be looked at (the caller checks).
using StreamWriter = std::function<void(std::ostream& out)>;

// Calls write(out) with a stream on a temporary file beside `target` (core/temporary_name.h), checks
// every write, the flush, fsync and close of it, then renames it over `target` and syncs the folder.
// Any failure (a full disk, a quota, no permission) removes the temporary file, leaves `target` as it
// was and throws InputError naming `target` and the reason; any other exception propagates the same
// way. Refuses (InputError) when `target` is one of `inputs`, so inputs are never overwritten. Every
// writer of the project's own bytes goes through here or write_files_atomically.
void write_stream_atomically(const std::filesystem::path& target, const StreamWriter& write,
                             const std::vector<std::filesystem::path>& inputs = {});

// For a file another program or library writes by name (ffmpeg): calls write(tmp_path), then fsyncs
// tmp_path and renames it over `target` as write_stream_atomically does. The writer must report its
// own failed writes (this cannot see a short file); prefer write_stream_atomically.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& tmp_path)>& write,
                      const std::vector<std::filesystem::path>& inputs = {});

// One file of a set that write_files_atomically replaces as a whole: write(out) produces its bytes
// (through a checked stream, as write_stream_atomically's).
struct FileWrite {
  std::filesystem::path target;
  StreamWriter write;
};

// Replaces every target of `files` (all in one directory) as a whole, also when the process is
// killed (SIGKILL, a crash): each file is written under a temporary name beside its target; then
// `journal` (a hidden file in that directory naming each temporary file and its target, and this
// process) is published with one rename, the moment the set changes; then each temporary file is
// renamed over its target and the journal removed. Killed before the journal is published, the
// targets are untouched and complete_interrupted_writes removes the temporary files; killed after,
// complete_interrupted_writes finishes the renames. It is called first, so a dead writer's leftovers
// are dealt with by the next write. Refuses (InputError) a target that is one of `inputs`.
// Each file is fsynced before the journal is published, and the folder after the renames.
void write_files_atomically(const std::filesystem::path& journal, const std::vector<FileWrite>& files,
                            const std::vector<std::filesystem::path>& inputs = {});

// What a writer killed inside write_files_atomically left beside `journal` and `targets`: a journal
// of a dead process is completed (its renames done, then it is removed); temporary files of dead
// processes for the journal and the targets (core/temporary_name.h: only names that are exactly ours,
// of a writer that is gone) are removed. Returns true when a
// journal was completed. Throws InputError when a live process's journal is pending (a writer is
// replacing the files right now) or when the renames fail.
bool complete_interrupted_writes(const std::filesystem::path& journal,
                                 const std::vector<std::filesystem::path>& targets);

// Convenience: atomically writes bytes or text.
void write_file_atomically(const std::filesystem::path& target, std::string_view contents,
                           const std::vector<std::filesystem::path>& inputs = {});

// Reads a whole file; InputError naming the file when it is missing, not a regular file (a directory,
// a FIFO, a device: core/input_file.h), unreadable, or larger than `max_bytes` (`why` says why).
std::string read_file(const std::filesystem::path& path, std::uint64_t max_bytes = kNoSizeBound,
                      std::string_view why = {});

// Lowercase hex SHA-256 of a file's bytes (body.json records the source mesh's hash).
std::string sha256_file(const std::filesystem::path& path);
// The same of bytes in memory (a mesh handed over as arrays, not as a file).
std::string sha256_hex(std::string_view bytes);

}  // namespace ts
