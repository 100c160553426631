// The CPU renderer against the GL renderer (on llvmpipe in CI) on the same scenes: the golden
// image's scene, and a level set with alpha, per-particle colours and a surface scalar.
//
// The tolerance, fixed before the first comparison ran: the mean absolute difference over all
// channels at most 2 / 255, and at most 2 % of the pixels with some channel more than 24 / 255
// apart. The two find the surface by different searches (NanoVDB's HDDA with sphere tracing and
// regula falsi in float, OpenVDB's level-set intersector with secant steps in double), so a
// silhouette or shadow edge may move by a pixel; the shading formulas are the same (look.h).
#include "preview/cpu_renderer.h"

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "core/error.h"
#include "core/mesh_io.h"
#include "preview/colors.h"
#include "preview/renderer.h"
#include "sdf/vdb_io.h"
#include "tests/test_support.h"

namespace ts::preview {
namespace {

constexpr double kMaxMeanDifference = 2.0;    // of 255, over all channels
constexpr double kMaxFractionOver = 0.02;     // of the pixels
constexpr int kDifferenceThreshold = 24;      // of 255, per channel

gpu::Context& context() {
  static gpu::Context c;
  return c;
}

// The golden image's scene (golden_test.cpp): a cube, particles along an edge and one above it.
Particles golden_particles() {
  Particles p;
  for (int i = 0; i < 5; ++i) p.centers.emplace_back(-0.04 + 0.02 * i, 0.05, 0.05 - 0.02 * i);
  p.centers.emplace_back(0.0, 0.09, 0.0);
  p.radii = {0.01f};
  return p;
}

RenderSettings golden_settings(const Aabb& content, int size) {
  RenderSettings s;
  s.up = Eigen::Vector3d::UnitY();
  s.width = s.height = size;
  s.camera = frame_box(content, view_direction(View::Iso, s.up), s.up, 1.0, false, 30.0);
  s.keep_buffers = true;
  return s;
}

// Both images are written to `dir` for a look when they differ.
void expect_images_agree(const RenderResult& cpu, const RenderResult& gl, const std::filesystem::path& dir,
                         const std::string& name) {
  ASSERT_EQ(cpu.image.width, gl.image.width);
  ASSERT_EQ(cpu.image.height, gl.image.height);
  const ImageDifference d = compare_images(cpu.image, gl.image, kDifferenceThreshold);
  write_png(dir / (name + "_cpu.png"), cpu.image);
  write_png(dir / (name + "_gl.png"), gl.image);
  EXPECT_LE(d.mean_abs, kMaxMeanDifference) << name << " in " << dir;
  EXPECT_LE(d.fraction_over, kMaxFractionOver) << name << " in " << dir;
  std::size_t layers_differ = 0;
  for (std::size_t i = 0; i < cpu.layers.size() && i < gl.layers.size(); ++i) layers_differ += cpu.layers[i] != gl.layers[i];
  EXPECT_LE(static_cast<double>(layers_differ), kMaxFractionOver * static_cast<double>(cpu.layers.size())) << name;
}

TEST(PreviewCpuRenderer, MatchesTheGlImageOfTheGoldenScene) {
  sdf::SdfSettings grid;
  grid.resolution = 40;
  const TriangleMesh cube = load_mesh(test::asset("cube.obj"));
  Renderer gl(context());
  CpuRenderer cpu;
  // Each renderer takes its volume; the scan conversion gives the same one twice.
  gl.load_volume(volume_from_mesh(context(), cube, grid));
  cpu.load_volume(volume_from_mesh(context(), cube, grid));
  gl.set_particles(golden_particles());
  cpu.set_particles(golden_particles());
  const std::filesystem::path dir = test::temp_dir();
  for (int size : {96, 200}) {
    const RenderSettings s = golden_settings(gl.content_box(), size);
    expect_images_agree(cpu.render(s), gl.render(s), dir, "golden_" + std::to_string(size));
  }
}

TEST(PreviewCpuRenderer, MatchesTheGlImageWithAlphaColoursAndASurfaceScalar) {
  sdf::ensure_openvdb_initialized();
  const auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.05f, openvdb::Vec3f(0.0f), 0.004f, 3.0f);
  Particles p;
  for (int i = 0; i < 12; ++i) {
    const double a = 0.5236 * i;
    p.centers.emplace_back(0.05 * std::cos(a), 0.05 * std::sin(a), 0.0);
    p.colors.push_back(pack_rgba8(categorical(static_cast<std::uint32_t>(i))));
  }
  p.radii = {0.008f};
  Renderer gl(context());
  CpuRenderer cpu;
  for (ImageRenderer* r : {static_cast<ImageRenderer*>(&gl), static_cast<ImageRenderer*>(&cpu)}) {
    r->load_volume(volume_from_level_set(*sphere, "sphere.vdb"));
    r->set_particles(p);
  }
  RenderSettings s = golden_settings(gl.content_box(), 128);
  s.up = Eigen::Vector3d::UnitZ();
  s.camera = frame_box(gl.content_box(), view_direction(View::Iso, s.up), s.up, 1.0, false, 30.0);
  s.alpha = true;
  s.surface_scalar.value = [](const Eigen::Vector3d& w) { return std::abs(w.z()); };
  s.surface_scalar.max_value = 0.05;
  const RenderResult from_cpu = cpu.render(s), from_gl = gl.render(s);
  expect_images_agree(from_cpu, from_gl, test::temp_dir(), "sphere_alpha");
  EXPECT_NEAR(static_cast<double>(from_cpu.scalar.pixels), static_cast<double>(from_gl.scalar.pixels),
              kMaxFractionOver * static_cast<double>(from_gl.scalar.pixels));
  EXPECT_NEAR(from_cpu.scalar.mean, from_gl.scalar.mean, 0.02 * 0.05);
}

// No gpu::Context anywhere in this test: the field from the exact SDF, the picture from the CPU.
TEST(PreviewCpuRenderer, DrawsAMeshAndParticlesWithoutAGlContext) {
  sdf::SdfSettings grid;
  grid.resolution = 40;
  CpuRenderer cpu;
  cpu.load_volume(volume_from_mesh_on_cpu(load_mesh(test::asset("cube.obj")), grid));
  cpu.set_particles(golden_particles());
  const RenderResult r = cpu.render(golden_settings(cpu.content_box(), 96));
  const auto count = [&](Layer layer) { return std::count(r.layers.begin(), r.layers.end(), layer); };
  EXPECT_GT(count(Layer::Surface), 96 * 96 / 10);
  EXPECT_GT(count(Layer::Particle), 20);
  EXPECT_GT(count(Layer::Background), 96 * 96 / 10);
}

TEST(PreviewCpuRenderer, AnEmptyFieldOrABadImageSizeIsAnInputError) {
  CpuRenderer cpu;
  EXPECT_THROW(cpu.load_volume(SdfVolume{}), InputError);
  EXPECT_THROW(cpu.check_image_size(0, 10), InputError);
  EXPECT_THROW(cpu.check_image_size(CpuRenderer::kMaxImageSide + 1, 10), InputError);
  RenderSettings s;
  EXPECT_THROW(cpu.render(s), InputError);  // nothing to draw
}

}  // namespace
}  // namespace ts::preview
