#pragma once
// Outputs are written atomically: to a temporary file beside the target, then renamed over it,
// so an interrupted run never leaves a half-written file and an existing output is replaced whole.
#include <filesystem>
#include <functional>
#include <string_view>
#include <vector>

namespace ts {

// Calls write(tmp_path) to produce the file, then renames tmp_path to `target`. On any exception
// the temporary file is removed and the exception propagates. Refuses (InputError) when `target`
// is one of `inputs`, so inputs are never overwritten.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& tmp_path)>& write,
                      const std::vector<std::filesystem::path>& inputs = {});

// One file of a set that write_files_atomically replaces as a whole: write(tmp_path) produces it.
struct FileWrite {
  std::filesystem::path target;
  std::function<void(const std::filesystem::path& tmp_path)> write;
};

// Replaces every target of `files` (all in one directory) as a whole, also when the process is
// killed (SIGKILL, a crash): each file is written under a temporary name beside its target; then
// `journal` (a hidden file in that directory naming each temporary file and its target, and this
// process) is published with one rename, the moment the set changes; then each temporary file is
// renamed over its target and the journal removed. Killed before the journal is published, the
// targets are untouched and complete_interrupted_writes removes the temporary files; killed after,
// complete_interrupted_writes finishes the renames. It is called first, so a dead writer's leftovers
// are dealt with by the next write. Refuses (InputError) a target that is one of `inputs`.
// Power loss is not covered: nothing is flushed to the disk before the renames.
void write_files_atomically(const std::filesystem::path& journal, const std::vector<FileWrite>& files,
                            const std::vector<std::filesystem::path>& inputs = {});

// What a writer killed inside write_files_atomically left beside `journal` and `targets`: a journal
// of a dead process is completed (its renames done, then it is removed); temporary files of dead
// processes for the journal and the targets (".NAME.tmp.PID.N") are removed. Returns true when a
// journal was completed. Throws InputError when a live process's journal is pending (a writer is
// replacing the files right now) or when the renames fail.
bool complete_interrupted_writes(const std::filesystem::path& journal,
                                 const std::vector<std::filesystem::path>& targets);

// Convenience: atomically writes bytes or text.
void write_file_atomically(const std::filesystem::path& target, std::string_view contents,
                           const std::vector<std::filesystem::path>& inputs = {});

// Reads a whole file; InputError naming the file when it is missing, a directory or unreadable.
std::string read_file(const std::filesystem::path& path);

// Lowercase hex SHA-256 of a file's bytes (body.json records the source mesh's hash).
std::string sha256_file(const std::filesystem::path& path);

}  // namespace ts
