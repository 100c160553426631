#pragma once
// What the fuzz targets share: a private scratch folder per process and files written into it. The
// targets feed libFuzzer's bytes to the project's readers through files, as a user's inputs arrive.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace ts::fuzz {

// A folder of this process's own, made on first use and removed at exit.
const std::filesystem::path& scratch_dir();

// Writes `bytes` to scratch_dir() / name (replacing it); returns the path.
std::filesystem::path scratch_file(const std::string& name, std::string_view bytes);

// libFuzzer's input as text.
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace ts::fuzz
