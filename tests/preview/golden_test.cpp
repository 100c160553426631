// One golden image guards the look as a whole (lighting, shadows, ground, compositing), compared with
// a tolerance: drivers round differently, so llvmpipe and an NVIDIA GPU need not agree bit for bit.
//
// Updating after an intended change of the look: rebuild, then run
//   TETRASAND_UPDATE_GOLDEN=1 build-test/bin/tetrasand_preview_tests --gtest_filter='PreviewGolden.*'
// which rewrites tests/preview/golden/*.png in the source tree; look at the new image, and commit it
// with the change that explains it (tests/preview/golden/README.md says the same).
#include <gtest/gtest.h>

#include <cstdlib>

#include "core/mesh_io.h"
#include "preview/renderer.h"
#include "tests/test_support.h"

namespace ts::preview {
namespace {

std::filesystem::path golden(const std::string& name) {
  return std::filesystem::path(TETRASAND_SOURCE_DIR) / "tests" / "preview" / "golden" / name;
}

void expect_matches_golden(const Image& image, const std::string& name) {
  const std::filesystem::path file = golden(name);
  const char* update = std::getenv("TETRASAND_UPDATE_GOLDEN");
  if (update && std::string(update) == "1") {
    write_png(file, image);
    GTEST_SKIP() << "rewrote " << file;
  }
  ASSERT_TRUE(std::filesystem::exists(file)) << file << " is missing; see the update procedure in golden_test.cpp";
  const Image expected = read_png(file);
  ASSERT_EQ(expected.width, image.width);
  ASSERT_EQ(expected.height, image.height);
  const ImageDifference d = compare_images(image, expected, 24);
  const std::filesystem::path actual = test::temp_dir() / name;
  write_png(actual, image);
  EXPECT_LE(d.mean_abs, 1.5) << "compare " << actual << " with " << file;
  EXPECT_LE(d.fraction_over, 0.01) << "compare " << actual << " with " << file;
}

TEST(PreviewGolden, CubeWithParticlesAndShadows) {
  gpu::Context context;
  Renderer renderer(context);
  sdf::SdfSettings grid;
  grid.resolution = 40;
  renderer.set_volume(volume_from_mesh(context, load_mesh(test::asset("cube.obj")), grid));
  Particles p;
  for (int i = 0; i < 5; ++i) p.centers.emplace_back(-0.04 + 0.02 * i, 0.05, 0.05 - 0.02 * i);  // along an edge
  p.centers.emplace_back(0.0, 0.09, 0.0);                                                          // floating above
  p.radii = {0.01f};
  renderer.set_particles(p);
  RenderSettings s;
  s.up =
      Eigen::Vector3d::UnitY();  // the golden was drawn y up (the cube is symmetric: any up tests the look)
  s.width = s.height = 96;
  s.camera = frame_box(renderer.content_box(), view_direction(View::Iso, s.up), s.up, 1.0, false, 30.0);
  expect_matches_golden(renderer.render(s).image, "cube_particles.png");
}

}  // namespace
}  // namespace ts::preview
