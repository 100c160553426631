// Mesh files through the project's loader (core/mesh_io.h load_mesh: the checks before assimp, assimp,
// the checks after it) and the report of what loaded. The first byte picks the format (the file's
// extension, which is how the loader and assimp choose a reader); the rest is the file.
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "core/error.h"
#include "core/log.h"
#include "core/mesh_io.h"
#include "core/mesh_report.h"
#include "fuzz/fuzz_support.h"

namespace {

constexpr const char* kExtensions[] = {"obj", "ply", "stl", "off", "gltf", "glb"};

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // assimp's OBJ reader allocates and fills 16 MiB for every read; see fuzz_support.h.
  if (ts::fuzz::reuse_large_blocks_in("libassimp.so") != 3)
    std::fprintf(stderr, "fuzz_mesh: assimp's operator new/delete not found; large blocks not reused\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  ts::log::set_level(ts::log::Level::Error);
  const char* extension = kExtensions[data[0] % std::size(kExtensions)];
  const auto file =
      ts::fuzz::scratch_file(std::string("mesh.") + extension, ts::fuzz::as_text(data + 1, size - 1));
  try {
    const ts::TriangleMesh mesh = ts::load_mesh(file);
    ts::ReportOptions options;
    options.self_intersections = false;  // CGAL's test is quadratic on what a fuzzer makes
    (void)ts::analyze_mesh(mesh, options);
  } catch (const ts::InputError&) {
    // A refused file is the expected outcome; a crash, a leak of another exception or a sanitizer
    // report is a finding.
  }
  return 0;
}
