// The renderer against geometry with known answers: silhouettes of orthographic views equal the
// analytic projected areas, shading normals equal the analytic normals, particles composite with
// the ray-cast surface by true depth, shadows fall, pixels repeat exactly. Runs on llvmpipe in CI,
// so images stay small.
#include "preview/renderer.h"

#include <gtest/gtest.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <numbers>

#include "core/error.h"
#include "core/mesh_io.h"
#include "sdf/vdb_io.h"
#include "tests/test_support.h"

namespace ts::preview {
namespace {

constexpr double kPi = std::numbers::pi;

gpu::Context& context() {
  static gpu::Context c;
  return c;
}

SdfVolume mesh_volume(const std::string& asset, int resolution) {
  sdf::SdfSettings grid;
  grid.resolution = resolution;
  return volume_from_mesh(context(), load_mesh(test::asset(asset)), grid);
}

// An orthographic camera looking along -from at `target`, `height` metres tall.
Camera ortho_camera(const Eigen::Vector3d& target, const Eigen::Vector3d& from, const Eigen::Vector3d& up,
                    double height) {
  Camera c;
  c.target = target;
  c.eye = target + from.normalized();
  c.up = up;
  c.ortho = true;
  c.ortho_height = height;
  return c;
}

RenderSettings ortho_settings(const Camera& camera, int size) {
  RenderSettings s;
  s.width = s.height = size;
  s.camera = camera;
  s.ground = false;
  s.keep_buffers = true;
  return s;
}

std::size_t count(const RenderResult& r, Layer layer) {
  return static_cast<std::size_t>(std::count(r.layers.begin(), r.layers.end(), layer));
}

double angle_degrees(const Eigen::Vector3f& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.cast<double>().normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / kPi;
}

// Fibonacci points on a sphere of radius R about the origin (even, deterministic).
std::vector<Eigen::Vector3d> fibonacci_sphere(int n, double radius) {
  std::vector<Eigen::Vector3d> p;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z);
    p.emplace_back(radius * r * std::cos(golden * i), radius * r * std::sin(golden * i), radius * z);
  }
  return p;
}

TEST(PreviewRenderer, SphereSilhouetteMatchesItsProjectedArea) {
  Renderer renderer(context());
  renderer.set_volume(mesh_volume("sphere.obj", 64));  // radius 5 cm
  const double height = 0.11;
  const int size = 192;
  const RenderResult r = renderer.render(
      ortho_settings(ortho_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), height), size));
  const double pixel = height / size;
  const double area = static_cast<double>(count(r, Layer::Surface)) * pixel * pixel;
  EXPECT_NEAR(area / (kPi * 0.05 * 0.05), 1.0, 0.01);
  EXPECT_EQ(count(r, Layer::Particle), 0u);
}

TEST(PreviewRenderer, CubeSilhouettesMatchTheirProjectedAreas) {
  Renderer renderer(context());
  renderer.set_volume(mesh_volume("cube.obj", 96));  // side 10 cm, centred at the origin
  const double a = 0.1;
  // Face on: a square; along a body diagonal: a regular hexagon of area sqrt(3) a^2.
  struct Case {
    Eigen::Vector3d from, up;
    double area, height;
  };
  for (const Case& c : {Case{Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), a * a, 0.12},
                        Case{Eigen::Vector3d(1, 1, 1), Eigen::Vector3d::UnitY(), std::sqrt(3.0) * a * a, 0.19}}) {
    const int size = 192;
    const RenderResult r = renderer.render(ortho_settings(ortho_camera(Eigen::Vector3d::Zero(), c.from, c.up, c.height), size));
    const double pixel = c.height / size;
    EXPECT_NEAR(static_cast<double>(count(r, Layer::Surface)) * pixel * pixel / c.area, 1.0, 0.01) << c.from.transpose();
  }
}

TEST(PreviewRenderer, ShadingNormalsMatchTheAnalyticNormals) {
  Renderer renderer(context());
  renderer.set_volume(mesh_volume("sphere.obj", 64));
  const double height = 0.11, radius = 0.05;
  const int size = 128;
  const RenderResult r = renderer.render(
      ortho_settings(ortho_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), height), size));
  // Image x is world x, image row 0 is the top (+y).
  const auto normal_at = [&](int px, int py) { return r.normals[static_cast<std::size_t>(py) * size + px]; };
  EXPECT_LT(angle_degrees(normal_at(size / 2, size / 2), Eigen::Vector3d::UnitZ()), 1.0);
  for (const auto& [px, py] : {std::pair{30, 64}, {100, 40}, {64, 110}, {45, 45}}) {
    const double x = (px + 0.5 - size / 2.0) * height / size, y = -(py + 0.5 - size / 2.0) * height / size;
    ASSERT_EQ(r.layers[static_cast<std::size_t>(py) * size + px], Layer::Surface);
    const Eigen::Vector3d analytic(x, y, std::sqrt(radius * radius - x * x - y * y));
    EXPECT_LT(angle_degrees(normal_at(px, py), analytic), 2.0) << px << " " << py;
  }

  Renderer cube(context());
  cube.set_volume(mesh_volume("cube.obj", 48));
  RenderSettings s = ortho_settings(
      ortho_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.2, 0.1, 1.0), Eigen::Vector3d::UnitY(), 0.2), 64);
  s.camera.ortho = false;  // a pinhole this time
  s.camera.eye = Eigen::Vector3d(0.06, 0.03, 0.3);
  const RenderResult c = cube.render(s);
  EXPECT_LT(angle_degrees(c.normals[32 * 64 + 32], Eigen::Vector3d::UnitZ()), 0.5);
}

TEST(PreviewRenderer, ParticlesShowOverTheSurfaceAndHideBehindIt) {
  Renderer renderer(context());
  renderer.set_volume(mesh_volume("sphere.obj", 48));
  const std::vector<Eigen::Vector3d> points = fibonacci_sphere(300, 0.05);
  Particles all;
  all.centers = points;
  all.radii = {0.004f};
  renderer.set_particles(all);
  const double height = 0.12;
  const int size = 128;
  const RenderSettings s =
      ortho_settings(ortho_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), height), size);
  const RenderResult front = renderer.render(s);
  const std::size_t particle = count(front, Layer::Particle), surface = count(front, Layer::Surface);
  // 300 spheres of 4 mm on a 5 cm sphere cover about 40 % of its disc; the surface shows between them.
  EXPECT_GT(particle, (particle + surface) / 4);
  EXPECT_GT(surface, (particle + surface) / 4);

  // Only particles on the far hemisphere: the surface hides every one inside the silhouette.
  Particles back;
  for (const auto& p : points)
    if (p.z() < -0.01) back.centers.push_back(p);
  back.radii = {0.004f};
  renderer.set_particles(back);
  const RenderResult hidden = renderer.render(s);
  std::size_t visible_inside = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double wx = (x + 0.5 - size / 2.0) * height / size, wy = (y + 0.5 - size / 2.0) * height / size;
      if (std::hypot(wx, wy) < 0.9 * 0.05 && hidden.layers[static_cast<std::size_t>(y) * size + x] == Layer::Particle) {
        ++visible_inside;
      }
    }
  }
  EXPECT_EQ(visible_inside, 0u);
}

TEST(PreviewRenderer, ImpostorsAreTrueSpheres) {
  Renderer renderer(context());
  Particles one;
  one.centers = {Eigen::Vector3d(1.0, 2.0, 3.0)};  // away from the origin: positions are relative on the GPU
  one.radii = {0.01f};
  renderer.set_particles(one);
  const double height = 0.03;
  const int size = 128;
  RenderSettings s = ortho_settings(ortho_camera(one.centers[0], Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), height), size);
  const RenderResult r = renderer.render(s);
  const double pixel = height / size;
  EXPECT_NEAR(static_cast<double>(count(r, Layer::Particle)) * pixel * pixel / (kPi * 1e-4), 1.0, 0.01);
  EXPECT_LT(angle_degrees(r.normals[64 * size + 64], Eigen::Vector3d::UnitZ()), 1.0);
  // A pinhole close by sees less than a hemisphere: the silhouette still closes around it.
  s.camera.ortho = false;
  s.camera.eye = one.centers[0] + Eigen::Vector3d(0, 0, 0.03);
  s.camera.fov_y = 60.0;
  const RenderResult near = renderer.render(s);
  const double expected = std::tan(std::asin(1.0 / 3.0)) / std::tan(kPi / 6.0) * size / 2.0;  // silhouette radius [px]
  EXPECT_NEAR(static_cast<double>(count(near, Layer::Particle)) / (kPi * expected * expected), 1.0, 0.02);
}

TEST(PreviewRenderer, PixelsRepeatExactly) {
  Renderer renderer(context());
  renderer.set_volume(mesh_volume("torus.obj", 48));
  Particles p;
  p.centers = fibonacci_sphere(50, 0.03);
  p.radii = {0.004f};
  renderer.set_particles(p);
  RenderSettings s;
  s.width = 96;
  s.height = 80;
  s.up = Eigen::Vector3d::UnitZ();
  s.camera = frame_box(renderer.content_box(), view_direction(View::Iso, s.up), s.up, 1.2, false, 30.0);
  const Image a = renderer.render(s).image;
  const Image b = renderer.render(s).image;
  Renderer again(context());
  again.set_volume(mesh_volume("torus.obj", 48));
  again.set_particles(p);
  EXPECT_EQ(a.rgba, b.rgba);
  EXPECT_EQ(a.rgba, again.render(s).image.rgba);
}

// A field larger than one storage block (a 2048-class level set on llvmpipe's 128 MiB) is uploaded in
// chunks, and the ray cast and shading programs are recompiled to read through them: the image must be
// the one a single block gives, pixel for pixel, shadows and particles included.
TEST(PreviewRenderer, AFieldCutIntoChunksRendersTheSameImageAsOneBlock) {
  Particles p;
  p.centers = fibonacci_sphere(40, 0.035);
  p.radii = {0.003f};
  RenderSettings s;
  s.width = 72;
  s.height = 64;
  s.up = Eigen::Vector3d::UnitZ();
  s.keep_buffers = true;

  Renderer whole(context());
  whole.set_volume(mesh_volume("torus.obj", 40));
  whole.set_particles(p);
  s.camera = frame_box(whole.content_box(), view_direction(View::Iso, s.up), s.up, 1.2, false, 30.0);
  const RenderResult a = whole.render(s);

  SdfVolume volume = mesh_volume("torus.obj", 40);
  const std::size_t bytes = volume.grid.size();
  Renderer chunked(context());
  chunked.set_volume(std::move(volume), bytes / 3);
  chunked.set_particles(p);
  const RenderResult b = chunked.render(s);

  EXPECT_EQ(whole.field_chunks(), 1);
  EXPECT_GE(chunked.field_chunks(), 3);
  EXPECT_GT(count(a, Layer::Surface), 500u);  // the torus fills part of the frame
  EXPECT_EQ(a.layers, b.layers);
  EXPECT_EQ(a.image.rgba, b.image.rgba);
}

TEST(PreviewRenderer, ShadowsDarkenTheGroundUnderTheLight) {
  Renderer renderer(context());
  Particles ball;
  ball.centers = {Eigen::Vector3d(0, 0, 0.05)};
  ball.radii = {0.02f};
  renderer.set_particles(ball);
  RenderSettings s;
  s.width = s.height = 96;
  s.up = Eigen::Vector3d::UnitZ();
  s.light = Eigen::Vector3d::UnitZ();  // straight down: the shadow is the disc under the ball
  s.ground_level = 0.0;
  Aabb view;
  view.extend(Eigen::Vector3d(-0.03, -0.03, 0.0));
  view.extend(Eigen::Vector3d(0.03, 0.03, 0.07));
  s.camera = frame_box(view, Eigen::Vector3d(0, -1, 1), s.up, 1.0, false, 40.0);
  s.keep_buffers = true;
  const RenderResult lit = renderer.render(s);
  s.shadows = false;
  const RenderResult flat = renderer.render(s);
  std::size_t darker = 0, brighter = 0;
  for (std::size_t i = 0; i < lit.layers.size(); ++i) {
    if (lit.layers[i] != Layer::Background) continue;
    const int d = int(flat.image.rgba[4 * i]) - int(lit.image.rgba[4 * i]);
    darker += d > 20 ? 1 : 0;
    brighter += d < -2 ? 1 : 0;
  }
  EXPECT_GT(darker, 100u);
  EXPECT_EQ(brighter, 0u);
}

TEST(PreviewRenderer, SurfaceScalarColoursEveryVisibleSurfacePixel) {
  Renderer renderer(context());
  renderer.set_volume(mesh_volume("sphere.obj", 48));
  RenderSettings s =
      ortho_settings(ortho_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), 0.11), 64);
  // The distance of the rendered surface from the true sphere, in voxels of the 48-voxel grid.
  const double h = 0.1 / 48;
  s.surface_scalar.value = [h](const Eigen::Vector3d& p) { return std::abs(p.norm() - 0.05) / h; };
  s.surface_scalar.max_value = 0.5;
  const RenderResult r = renderer.render(s);
  EXPECT_EQ(r.scalar.pixels, count(r, Layer::Surface));
  EXPECT_LT(r.scalar.mean, 0.05);  // the icosphere sits inside the sphere by at most 0.03 voxels here
  EXPECT_LT(r.scalar.max, 0.2);
}

TEST(PreviewRenderer, LevelSetFilesRenderLikeMeshes) {
  sdf::ensure_openvdb_initialized();
  const auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.05f, openvdb::Vec3f(0.2f, 0.0f, 0.0f),
                                                                             0.002f, 3.0f);
  SdfVolume volume = volume_from_level_set(*grid, "sphere.vdb");
  EXPECT_NEAR(volume.band, 3.0, 1e-6);
  Renderer renderer(context());
  renderer.set_volume(std::move(volume));
  const double height = 0.11;
  const int size = 160;
  const RenderResult r = renderer.render(ortho_settings(
      ortho_camera(Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), height), size));
  const double pixel = height / size;
  EXPECT_NEAR(static_cast<double>(count(r, Layer::Surface)) * pixel * pixel / (kPi * 0.05 * 0.05), 1.0, 0.01);
}

TEST(PreviewRenderer, RotatedOrEmptyLevelSetsAreRefused) {
  sdf::ensure_openvdb_initialized();
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 0.1f, 3.0f);
  EXPECT_NO_THROW(volume_from_level_set(*grid, "sphere.vdb"));
  openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(0.1);
  t->preRotate(0.3, openvdb::math::Z_AXIS);
  grid->setTransform(t);
  EXPECT_THROW(volume_from_level_set(*grid, "rotated.vdb"), InputError);
  const auto empty = openvdb::createLevelSet<openvdb::FloatGrid>(0.1, 3.0);
  EXPECT_THROW(volume_from_level_set(*empty, "empty.vdb"), InputError);
}

// Two small spheres 4000 voxels apart along each axis: a box of about 4046^3 voxels, whose dense
// copy would need 246 GiB. The sparse field holds the two bands only, and the HDDA
// crosses the empty space between them.
TEST(PreviewRenderer, LevelSetsWhoseBoxNoDenseCopyHoldsRenderSparse) {
  sdf::ensure_openvdb_initialized();
  const float h = 0.001f;
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.02f, openvdb::Vec3f(0.0f), h, 3.0f);
  const auto far = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.02f, openvdb::Vec3f(4.0f, 4.0f, 4.0f), h, 3.0f);
  openvdb::tools::csgUnion(*grid, *far->deepCopy());
  SdfVolume volume = volume_from_level_set(*grid, "two_spheres.vdb");
  EXPECT_GT(volume.spec.voxel_count(), std::size_t{60} << 30);
  EXPECT_LT(volume.grid.size(), std::size_t{16} << 20);
  Renderer renderer(context());
  renderer.set_volume(std::move(volume));
  // Looking along -y at the far sphere, framed tightly: a disc of its radius, found across the box.
  const double height = 0.05;
  const int size = 96;
  const RenderResult r = renderer.render(ortho_settings(
      ortho_camera(Eigen::Vector3d(4.0, 4.0, 4.0), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), height), size));
  const double pixel = height / size;
  EXPECT_NEAR(static_cast<double>(count(r, Layer::Surface)) * pixel * pixel / (kPi * 0.02 * 0.02), 1.0, 0.03);
}

TEST(PreviewRenderer, ImageSizesOutsideTheDeviceLimitsAreInputErrors) {
  Renderer renderer(context());
  const Eigen::Vector2i max = renderer.max_image_size();
  EXPECT_GE(max.minCoeff(), 1024);
  EXPECT_THROW(renderer.check_image_size(0, 10), InputError);
  EXPECT_THROW(renderer.check_image_size(max.x() + 1, 10), InputError);
  EXPECT_NO_THROW(renderer.check_image_size(max.x(), 1));
  // Nothing loaded: nothing to render.
  RenderSettings s;
  EXPECT_THROW(renderer.render(s), InputError);
}

}  // namespace
}  // namespace ts::preview
