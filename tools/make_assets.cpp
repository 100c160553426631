// Writes the generated assets: `tetrasand_make_assets OUTDIR` (scripts/make_assets.sh runs it).
#include <fmt/format.h>

#include <filesystem>

#include "core/mesh_io.h"
#include "core/primitives.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    fmt::print(stderr, "usage: {} OUTDIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path out = argv[1];
  std::filesystem::create_directories(out);
  // Sizes in metres, a few thousand triangles each: small enough for tests on llvmpipe.
  ts::write_obj(out / "sphere.obj", ts::make_icosphere(0.05, 4));                          // r = 5 cm, 5120 tris
  ts::write_obj(out / "cube.obj", ts::make_box({-0.05, -0.05, -0.05}, {0.05, 0.05, 0.05}));  // 10 cm, 12 tris
  ts::write_obj(out / "torus.obj", ts::make_torus(0.06, 0.02, 64, 24));                     // 3072 tris
  ts::write_obj(out / "trefoil.obj", ts::make_trefoil_tube(0.02, 0.012, 192, 16));           // 6144 tris
  ts::write_obj(out / "plate.obj", ts::make_plate(0.1, 0.06, 0.002, 10, 6));                // 2 mm thin plate
  ts::write_obj(out / "slab.obj", ts::make_box({-0.04, -0.025, 0.0}, {0.04, 0.025, 0.016}));  // 8 x 5 x 1.6 cm layer
  fmt::print("wrote sphere, cube, torus, trefoil, plate, slab to {}\n", out.string());
  return 0;
}
