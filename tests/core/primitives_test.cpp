// Generated meshes are closed, outward, of the right topology and size; the bundled assets are what
// their generators make today.
#include "core/primitives.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/mass_properties.h"
#include "core/mesh_io.h"
#include "core/mesh_report.h"
#include "tests/test_support.h"

namespace ts {
namespace {

void expect_watertight(const TriangleMesh& mesh, int genus, const char* what) {
  const MeshReport r = analyze_mesh(mesh);
  EXPECT_TRUE(r.watertight()) << what << "\n" << format_report(r);
  EXPECT_EQ(r.components, 1u) << what;
  EXPECT_EQ(r.genus, genus) << what;
  EXPECT_EQ(r.degenerate_triangles, 0u) << what;
}

TEST(Primitives, BoxIsClosedOutwardAndExact) {
  const TriangleMesh box = make_box(Eigen::Vector3d(0.2, 0.4, 0.1));
  expect_watertight(box, 0, "box");
  EXPECT_EQ(box.triangle_count(), 12u);
  EXPECT_NEAR(signed_volume(box), 0.2 * 0.4 * 0.1, 1e-17);
  EXPECT_NEAR(surface_area(box), 2 * (0.08 + 0.02 + 0.04), 1e-15);
  const Aabb aabb = bounding_box(box);
  EXPECT_LT((aabb.center()).norm(), 1e-17);
  EXPECT_LT((aabb.size() - Eigen::Vector3d(0.2, 0.4, 0.1)).norm(), 1e-16);
}

TEST(Primitives, IcosphereIsInscribedAndConverges) {
  const double r = 0.05, sphere = 4.0 / 3.0 * M_PI * r * r * r;
  double previous_deficit = 1.0;  // the icosahedron itself misses 40 %
  for (int s = 0; s <= 4; ++s) {
    const TriangleMesh mesh = make_icosphere(r, s);
    EXPECT_EQ(mesh.triangle_count(), 20u << (2 * s));
    for (const auto& v : mesh.vertices) ASSERT_NEAR(v.norm(), r, 1e-15);
    const double deficit = 1.0 - signed_volume(mesh) / sphere;
    EXPECT_GT(deficit, 0.0);
    if (s > 0) {
      EXPECT_LT(deficit, previous_deficit / 3.0) << s;  // the chord error falls by ~4 per subdivision
    }
    previous_deficit = deficit;
  }
  expect_watertight(make_icosphere(r, 3), 0, "icosphere");
}

TEST(Primitives, TorusHasGenusOneAndConvergesToItsVolume) {
  const double major = 0.06, minor = 0.02, exact = 2.0 * M_PI * M_PI * major * minor * minor;
  expect_watertight(make_torus(major, minor, 32, 12), 1, "torus");
  const double coarse = std::abs(signed_volume(make_torus(major, minor, 32, 12)) / exact - 1.0);
  const double fine = std::abs(signed_volume(make_torus(major, minor, 128, 48)) / exact - 1.0);
  EXPECT_LT(coarse, 0.06);
  EXPECT_LT(fine, coarse / 10.0);
}

TEST(Primitives, TrefoilTubeIsAKnottedSolidWithoutSelfIntersections) {
  const TriangleMesh knot = make_trefoil_tube(0.02, 0.012, 96, 12);
  expect_watertight(knot, 1, "trefoil");
  // A tube of radius a along a curve of length L encloses about pi a^2 L.
  double length = 0.0;
  const int n = 4096;
  auto curve = [](double t) -> Eigen::Vector3d {  // not an Eigen expression over a temporary
    return 0.02 * Eigen::Vector3d(std::sin(t) + 2 * std::sin(2 * t), std::cos(t) - 2 * std::cos(2 * t), -std::sin(3 * t));
  };
  for (int i = 0; i < n; ++i) length += (curve(2 * M_PI * (i + 1) / n) - curve(2 * M_PI * i / n)).norm();
  EXPECT_NEAR(signed_volume(knot) / (M_PI * 0.012 * 0.012 * length), 1.0, 0.06);
}

TEST(Primitives, PlateIsAThinClosedBox) {
  const TriangleMesh plate = make_plate(0.1, 0.06, 0.002, 10, 6);
  expect_watertight(plate, 0, "plate");
  EXPECT_NEAR(signed_volume(plate), 0.1 * 0.06 * 0.002, 1e-15);
  EXPECT_NEAR(bounding_box(plate).size().z(), 0.002, 1e-15);
}

TEST(Primitives, BundledAssetsMatchTheirGenerators) {
  // Same parameters as tools/make_assets.cpp: a stale or hand-edited asset fails here.
  const std::pair<const char*, TriangleMesh> assets[] = {
      {"sphere.obj", make_icosphere(0.05, 4)},
      {"cube.obj", make_box({-0.05, -0.05, -0.05}, {0.05, 0.05, 0.05})},
      {"torus.obj", make_torus(0.06, 0.02, 64, 24)},
      {"trefoil.obj", make_trefoil_tube(0.02, 0.012, 192, 16)},
      {"plate.obj", make_plate(0.1, 0.06, 0.002, 10, 6)},
      {"slab.obj", make_box({-0.04, -0.025, 0.0}, {0.04, 0.025, 0.016})},
  };
  for (const auto& [file, generated] : assets) {
    const TriangleMesh loaded = load_mesh(test::asset(file));
    ASSERT_EQ(loaded.triangle_count(), generated.triangle_count()) << file;
    ASSERT_EQ(loaded.vertex_count(), generated.vertex_count()) << file;
    // Assimp renumbers vertices and reads positions as float: compare the sorted sets of positions.
    auto sorted_positions = [](const TriangleMesh& mesh) {
      std::vector<Eigen::Vector3d> p;
      for (const auto& v : mesh.vertices) p.push_back(v.cast<float>().cast<double>());
      std::sort(p.begin(), p.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
        return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
      });
      return p;
    };
    const auto a = sorted_positions(loaded), b = sorted_positions(generated);
    double max_difference = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) max_difference = std::max(max_difference, (a[i] - b[i]).norm());
    EXPECT_LT(max_difference, 1e-8) << file;  // assimp's float parser is not correctly rounded
    EXPECT_NEAR(signed_volume(loaded) / signed_volume(generated), 1.0, 1e-6) << file;
    EXPECT_LE(loaded.triangle_count(), 10000u) << file;
  }
}

TEST(Primitives, BundledBunnyIsTheClosedStanfordBunny) {
  const TriangleMesh bunny = load_mesh(test::asset("bunny.obj"));
  EXPECT_EQ(bunny.triangle_count(), 3674u);
  const MeshReport r = analyze_mesh(bunny);
  EXPECT_TRUE(r.watertight()) << format_report(r);
  EXPECT_EQ(r.genus, 0);
  EXPECT_NEAR(r.box.size().maxCoeff(), 0.10, 0.01);  // about 10 cm, in metres
}

}  // namespace
}  // namespace ts
