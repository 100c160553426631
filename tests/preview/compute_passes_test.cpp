// The compute shadow map and G-buffer (preview/compute_passes.h) against the draws, in one renderer on
// one device (llvmpipe in CI), on the scenes of the existing goldens.
//
// The tolerance, fixed before the first comparison ran (docs/benchmarks/preview.md, "Compute passes
// against the raster passes"): the mean absolute difference over all channels at most 1 / 255, at
// most 0.5 % of the pixels with some channel more than 24 / 255 apart, and at most 0.5 % of the pixels
// in another layer. Both paths march the same code (shaders/preview/march.glsl) and hit the same
// spheres; a silhouette may move by a pixel where the rasteriser's coverage rules and the slab test
// disagree about a ray that grazes the box or a sphere.
#include "preview/compute_passes.h"

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <algorithm>
#include <cmath>

#include "core/mesh_io.h"
#include "preview/colors.h"
#include "preview/renderer.h"
#include "sdf/vdb_io.h"
#include "tests/test_support.h"

namespace ts::preview {
namespace {

constexpr double kMaxMeanDifference = 1.0;  // of 255, over all channels
constexpr double kMaxFractionOver = 0.005;  // of the pixels
constexpr int kDifferenceThreshold = 24;    // of 255, per channel

gpu::Context& context() {
  static gpu::Context c;
  return c;
}

RenderSettings iso_settings(const Aabb& content, const Eigen::Vector3d& up, int size) {
  RenderSettings s;
  s.up = up;
  s.width = s.height = size;
  s.camera = frame_box(content, view_direction(View::Iso, s.up), s.up, 1.0, false, 30.0);
  s.keep_buffers = true;
  return s;
}

// Renders `s` by both paths of `renderer`; both images are written to the test's temporary folder.
void expect_paths_agree(Renderer& renderer, const RenderSettings& s, const std::string& name) {
  renderer.set_gpu_path(GpuPath::Raster);
  const RenderResult raster = renderer.render(s);
  renderer.set_gpu_path(GpuPath::Compute);
  const RenderResult compute = renderer.render(s);
  const std::filesystem::path dir = test::temp_dir();
  write_png(dir / (name + "_raster.png"), raster.image);
  write_png(dir / (name + "_compute.png"), compute.image);
  const ImageDifference d = compare_images(compute.image, raster.image, kDifferenceThreshold);
  EXPECT_LE(d.mean_abs, kMaxMeanDifference) << name << " in " << dir;
  EXPECT_LE(d.fraction_over, kMaxFractionOver) << name << " in " << dir;
  ASSERT_EQ(compute.layers.size(), raster.layers.size());
  std::size_t layers_differ = 0, particles = 0, surface = 0;
  for (std::size_t i = 0; i < raster.layers.size(); ++i) {
    layers_differ += compute.layers[i] != raster.layers[i];
    particles += compute.layers[i] == Layer::Particle;
    surface += compute.layers[i] == Layer::Surface;
  }
  EXPECT_LE(static_cast<double>(layers_differ), kMaxFractionOver * static_cast<double>(raster.layers.size())) << name;
  // The comparison means something only when both kinds of content are in the picture.
  EXPECT_GT(particles, 0u) << name;
  EXPECT_GT(surface, 0u) << name;
}

TEST(PreviewComputePasses, MatchTheDrawsOnTheGoldenScene) {
  sdf::SdfSettings grid;
  grid.resolution = 40;
  Renderer renderer(context());
  renderer.set_volume(volume_from_mesh(context(), load_mesh(test::asset("cube.obj")), grid));
  Particles p;  // golden_test.cpp's: along an edge of the cube, and one floating above it
  for (int i = 0; i < 5; ++i) p.centers.emplace_back(-0.04 + 0.02 * i, 0.05, 0.05 - 0.02 * i);
  p.centers.emplace_back(0.0, 0.09, 0.0);
  p.radii = {0.01f};
  renderer.set_particles(p);
  for (int size : {96, 128}) {
    expect_paths_agree(renderer, iso_settings(renderer.content_box(), Eigen::Vector3d::UnitY(), size),
                       "golden_" + std::to_string(size));
  }
}

TEST(PreviewComputePasses, MatchTheDrawsWithAlphaColoursAndASurfaceScalar) {
  sdf::ensure_openvdb_initialized();
  const auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.05f, openvdb::Vec3f(0.0f), 0.004f, 3.0f);
  Particles p;  // cpu_renderer_test.cpp's ring of coloured particles around the sphere
  for (int i = 0; i < 12; ++i) {
    const double a = 0.5236 * i;
    p.centers.emplace_back(0.05 * std::cos(a), 0.05 * std::sin(a), 0.0);
    p.colors.push_back(pack_rgba8(categorical(static_cast<std::uint32_t>(i))));
  }
  p.radii = {0.008f};
  Renderer renderer(context());
  renderer.set_volume(volume_from_level_set(*sphere, "sphere.vdb"));
  renderer.set_particles(p);
  RenderSettings s = iso_settings(renderer.content_box(), Eigen::Vector3d::UnitZ(), 128);
  s.alpha = true;
  s.surface_scalar.value = [](const Eigen::Vector3d& w) { return std::abs(w.z()); };
  s.surface_scalar.max_value = 0.05;
  expect_paths_agree(renderer, s, "sphere_alpha");
}

TEST(PreviewComputePasses, OverlappingSpheresResolveToTheNearestWhateverTheirOrder) {
  // Three spheres on the camera's axis: the nearest must cover the middle pixel, in either order.
  Particles p;
  p.centers = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.03}, {0.0, 0.0, -0.03}};
  p.colors = {pack_rgba8({1.0f, 0.0f, 0.0f}), pack_rgba8({0.0f, 1.0f, 0.0f}), pack_rgba8({0.0f, 0.0f, 1.0f})};
  p.radii = {0.02f};
  Renderer renderer(context());
  renderer.set_gpu_path(GpuPath::Compute);
  for (bool reversed : {false, true}) {
    Particles q = p;
    if (reversed) {
      std::reverse(q.centers.begin(), q.centers.end());
      std::reverse(q.colors.begin(), q.colors.end());
    }
    renderer.set_particles(q);
    RenderSettings s = iso_settings(renderer.content_box(), Eigen::Vector3d::UnitY(), 64);
    s.camera = frame_box(renderer.content_box(), Eigen::Vector3d::UnitZ(), s.up, 1.0, false, 30.0);
    s.shadows = false;
    s.ground = false;
    const RenderResult r = renderer.render(s);
    const std::size_t middle = 32 * 64 + 32;
    ASSERT_EQ(r.layers[middle], Layer::Particle);
    const std::uint8_t* rgba = &r.image.rgba[4 * middle];
    EXPECT_GT(rgba[1], rgba[0]) << "reversed " << reversed << ": the green sphere (z = 0.03) is nearest";
    EXPECT_GT(rgba[1], rgba[2]) << "reversed " << reversed;
  }
}

TEST(PreviewComputePasses, GpuPathSpellingsRoundTripAndOthersAreRefused) {
  for (GpuPath path : {GpuPath::Auto, GpuPath::Raster, GpuPath::Compute}) {
    EXPECT_EQ(parse_gpu_path(gpu_path_name(path)), path);
  }
  EXPECT_FALSE(parse_gpu_path("fragment").has_value());
}

}  // namespace
}  // namespace ts::preview
