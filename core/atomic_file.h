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

// Convenience: atomically writes bytes or text.
void write_file_atomically(const std::filesystem::path& target, std::string_view contents,
                           const std::vector<std::filesystem::path>& inputs = {});

// Reads a whole file; InputError naming the file when it is missing, a directory or unreadable.
std::string read_file(const std::filesystem::path& path);

// Lowercase hex SHA-256 of a file's bytes (body.json records the source mesh's hash).
std::string sha256_file(const std::filesystem::path& path);

}  // namespace ts
