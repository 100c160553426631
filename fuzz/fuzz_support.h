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

// Makes the operator new and delete that the shared library whose path contains `library` calls
// (through its GOT; the program's own calls are untouched) keep the last block of 8 MiB or more that it
// frees and hand it out again for a request of exactly its size, instead of ASan mapping a fresh block
// (and the kernel zeroing it) each time. assimp's OBJ reader allocates and fills 16 MiB for every read
// (IOStreamBuffer's cache), page faults that were most of fuzz_mesh's time. Everything else goes to the
// program's operator new and delete (ASan's) unchanged; the kept block is poisoned while kept (a use
// of it after delete is reported as use-after-poison) and, handed out at its own size only, keeps its
// redzones. Returns the number of GOT slots redirected (3 when all were found, 0 if none).
int reuse_large_blocks_in(const char* library);

// libFuzzer's input as text.
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace ts::fuzz
