// The CPU coverage certifier (sampler/cpu_coverage_certificate.h) beside the GPU one on the same
// inputs: the same verdict, bounds within the floor of each other (each lies within
// max(r, c) / floor_divisor + its margin above c), and the same holes; then the cases only it must
// answer for (zero-area and single triangles, the thread count). Its known-answer cases are those of
// gpu_coverage_certificate_test.cpp, which run against both certifiers.
#include "sampler/cpu_coverage_certificate.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "core/error.h"
#include "core/mesh_io.h"
#include "sampler/gpu_coverage_certificate.h"
#include "sampler/sampling_quality.h"
#include "sampler/surface_points.h"
#include "tests/test_meshes.h"
#include "tests/test_support.h"

namespace ts::sampler {
namespace {

gpu::Context& shared_context() {
  static gpu::Context context;
  return context;
}

std::vector<Eigen::Vector3f> to_float(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : points) out.push_back(p.cast<float>());
  return out;
}

// How far apart two certificates of the same input may be: each bound lies in
// [c, c + max(r, c) / floor_divisor + its margin], and c is at least either lower figure.
double agreement_tolerance(const CoverageCertificate& a, const CoverageCertificate& b) {
  const double c_at_least = std::max(a.covering_lower, b.covering_lower);
  return std::max(a.radius, c_at_least) / 64.0 + a.margin + b.margin;
}

// Whether `x` (a point of the surface) lies in one of `pieces`: within a piece's longest edge of
// its centroid (every point of a piece is), a necessary condition that is enough to tell holes apart.
bool near_a_piece(const Eigen::Vector3d& x, const std::vector<UncoveredPiece>& pieces) {
  return std::any_of(pieces.begin(), pieces.end(), [&](const UncoveredPiece& p) {
    return (p.position - x).norm() <= p.edge * (1.0 + 1e-9);
  });
}

// The same verdict, bounds within the tolerance of each other, lower figures below the other's
// bound; with holes, the deepest of each within the floor of the other's, and every hole point one
// certifier locates deeper than r lying in a piece the other reports (a point deeper than r is
// uncovered, so each certifier's final pieces hold it in an uncovered one).
void expect_agreement(const CoverageCertificate& gpu, const CoverageCertificate& cpu,
                      std::span<const Eigen::Vector3f> centres) {
  const double tolerance = agreement_tolerance(gpu, cpu);
  EXPECT_EQ(gpu.covered, cpu.covered);
  EXPECT_NEAR(gpu.covering_bound, cpu.covering_bound, tolerance);
  EXPECT_LE(gpu.covering_lower, cpu.covering_bound);
  EXPECT_LE(cpu.covering_lower, gpu.covering_bound);
  EXPECT_EQ(cpu.tiles, 1u);
  EXPECT_FALSE(cpu.budget_reached);
  std::printf(
      "  r %.5g: GPU bound %.6g lower %.6g (%zu pieces, %zu evaluated); CPU bound %.6g lower %.6g (%zu "
      "pieces, %zu evaluated); tolerance %.3g\n",
      gpu.radius, gpu.covering_bound, gpu.covering_lower, gpu.uncovered, gpu.evaluated, cpu.covering_bound,
      cpu.covering_lower, cpu.uncovered, cpu.evaluated, tolerance);
  if (gpu.covered || cpu.covered) return;
  const std::vector<UncoveredPiece> gpu_holes = deepest_holes(gpu, centres, 1000);
  const std::vector<UncoveredPiece> cpu_holes = deepest_holes(cpu, centres, 1000);
  ASSERT_FALSE(gpu_holes.empty());
  ASSERT_FALSE(cpu_holes.empty());
  EXPECT_NEAR(gpu_holes.front().depth, cpu_holes.front().depth, gpu.floor);
  for (const UncoveredPiece& h : cpu_holes) {
    if (h.depth > gpu.radius) {
      EXPECT_TRUE(near_a_piece(h.position, gpu.pieces)) << h.position.transpose();
    }
  }
  for (const UncoveredPiece& h : gpu_holes) {
    if (h.depth > cpu.radius) {
      EXPECT_TRUE(near_a_piece(h.position, cpu.pieces)) << h.position.transpose();
    }
  }
}

TEST(CpuCoverageCertificate, AgreesWithTheGpuOnIcosahedralSetsOnASphere) {
  const TriangleMesh sphere = test::icosphere(1.0, 4);
  GpuCoverageCertifier gpu(shared_context(), sphere);
  CpuCoverageCertifier cpu(sphere);
  for (const std::size_t n : {std::size_t{12}, std::size_t{42}}) {
    const std::vector<Eigen::Vector3f> centres =
        to_float(std::vector<Eigen::Vector3d>(sphere.vertices.begin(), sphere.vertices.begin() + n));
    // Above and below the covering radius (0.64 for 12 centres), away from it.
    CoverageSettings probes;
    probes.probes = 200'000;
    const double sampled = measure_coverage(sphere, centres, probes).covering_radius;
    for (const double r : {1.15 * sampled, 0.9 * sampled}) {
      const CoverageCertificate a = gpu.certify(centres, r), b = cpu.certify(centres, r);
      expect_agreement(a, b, centres);
      if (n == 12 && r < sampled) {
        // The 20 face centres, one hole each, in both.
        EXPECT_EQ(deepest_holes(b, centres, 100).size(), 20u);
        EXPECT_EQ(deepest_holes(a, centres, 100).size(), 20u);
      }
    }
  }
}

// The bunny with 300 area-uniform seeded points: a real mesh with triangles of every shape, covered
// at a radius well above its covering radius and full of holes well below it.
TEST(CpuCoverageCertificate, AgreesWithTheGpuOnTheBunny) {
  const TriangleMesh bunny = load_mesh(test::asset("bunny.obj"));
  std::mt19937_64 rng(21);
  const std::vector<Eigen::Vector3d> points = sample_surface_points(bunny, 300, rng).positions;
  const std::vector<Eigen::Vector3f> centres = to_float(points);
  CoverageSettings probes;
  probes.probes = 200'000;
  const double sampled = measure_coverage(bunny, centres, probes).covering_radius;
  GpuCoverageCertifier gpu(shared_context(), bunny);
  CpuCoverageCertifier cpu(bunny);
  for (const double r : {1.25 * sampled, 0.8 * sampled}) {
    const CoverageCertificate a = gpu.certify(centres, r), b = cpu.certify(centres, r);
    EXPECT_GE(b.covering_bound, sampled);
    EXPECT_EQ(b.covered, r > sampled);
    expect_agreement(a, b, centres);
  }
}

// Zero-area triangles (three collinear vertices, three equal ones) and a mesh of one triangle:
// known answers, finite figures, no hang.
TEST(CpuCoverageCertificate, ZeroAreaAndSingleTrianglesHaveTheirKnownCoveringRadius) {
  // A segment from (0,0,0) to (1,0,0) as a triangle, centres at its ends: c = 0.5, at its middle.
  TriangleMesh segment;
  segment.vertices = {{0, 0, 0}, {1, 0, 0}, {0.25, 0, 0}};
  segment.triangles = {{0, 1, 2}};
  const std::vector<Eigen::Vector3f> ends = {{0, 0, 0}, {1, 0, 0}};
  CpuCoverageCertifier on_segment(segment);
  for (const double r : {0.6, 0.4}) {
    const CoverageCertificate cert = on_segment.certify(ends, r);
    EXPECT_EQ(cert.covered, r > 0.5);
    EXPECT_GE(cert.covering_bound, 0.5);
    EXPECT_LE(cert.covering_bound, 0.5 + std::max(r, 0.5) / 64.0 + cert.margin);
    EXPECT_LE(cert.covering_lower, 0.5);
    EXPECT_EQ(cert.uncovered_area, 0.0);
    for (const UncoveredPiece& p : cert.pieces) {
      EXPECT_TRUE(p.position.allFinite() && std::isfinite(p.depth) && std::isfinite(p.bound));
      EXPECT_TRUE(p.normal.isZero(0.0));  // no face to take it from
    }
  }
  // Three equal vertices: one point, 0.3 from the nearest centre.
  TriangleMesh point;
  point.vertices = {{0.2, 0.3, 0}, {0.2, 0.3, 0}, {0.2, 0.3, 0}};
  point.triangles = {{0, 1, 2}};
  CpuCoverageCertifier on_point(point);
  const std::vector<Eigen::Vector3f> centre = {{0.2f, 0.0f, 0.0f}, {5.0f, 5.0f, 5.0f}};
  const double d = (Eigen::Vector3d(0.2, 0.3, 0) - centre[0].cast<double>()).norm();
  for (const double r : {1.2 * d, 0.8 * d}) {
    const CoverageCertificate cert = on_point.certify(centre, r);
    EXPECT_EQ(cert.covered, r > d);
    EXPECT_NEAR(cert.covering_bound, d, 1e-9);
    EXPECT_NEAR(cert.covering_lower, d, 1e-9);
    EXPECT_EQ(cert.levels, 1);
  }
  // One equilateral triangle of circumradius 1 with a centre at its centroid: c = 1, at the corners.
  TriangleMesh triangle;
  for (const double degrees : {90.0, 210.0, 330.0}) {
    const double a = degrees * M_PI / 180.0;
    triangle.vertices.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  triangle.triangles = {{0, 1, 2}};
  CpuCoverageCertifier on_triangle(triangle);
  const std::vector<Eigen::Vector3f> centroid = {{0, 0, 0}};
  for (const double r : {1.1, 0.9}) {
    const CoverageCertificate cert = on_triangle.certify(centroid, r);
    EXPECT_EQ(cert.covered, r > 1.0);
    EXPECT_GE(cert.covering_bound, 1.0);
    EXPECT_LE(cert.covering_bound, 1.0 + std::max(r, 1.0) / 64.0 + cert.margin);
    EXPECT_LE(cert.covering_lower, 1.0);
    if (r < 1.0) {
      // The three corner regions beyond r, each holding the annulus' share of the triangle.
      EXPECT_EQ(deepest_holes(cert, centroid, 10).size(), 3u);
      EXPECT_GT(cert.uncovered_area, 0.0);
    }
  }
}

TEST(CpuCoverageCertificate, SameInputGivesTheSameBitsWhateverTheThreadCount) {
  const TriangleMesh sphere = test::icosphere(1.0, 3);
  std::mt19937_64 rng(3);
  const std::vector<Eigen::Vector3f> centres = to_float(sample_surface_points(sphere, 80, rng).positions);
  CpuCoverageCertifier certifier(sphere);
  for (const double r : {0.2, 0.4}) {
    const CoverageCertificate many = certifier.certify(centres, r);
    CoverageCertificate one;
    tbb::task_arena single(1);
    single.execute([&] { one = certifier.certify(centres, r); });
    EXPECT_EQ(many.covered, one.covered);
    EXPECT_EQ(many.covering_bound, one.covering_bound);
    EXPECT_EQ(many.covering_lower, one.covering_lower);
    EXPECT_EQ(many.evaluated, one.evaluated);
    ASSERT_EQ(many.pieces.size(), one.pieces.size());
    for (std::size_t k = 0; k < many.pieces.size(); ++k) {
      EXPECT_EQ(many.pieces[k].position, one.pieces[k].position);
      EXPECT_EQ(many.pieces[k].bound, one.pieces[k].bound);
      EXPECT_EQ(many.pieces[k].depth, one.pieces[k].depth);
    }
  }
}

TEST(CpuCoverageCertificate, RejectsCentresAndVerticesThatAreNotFinite) {
  const TriangleMesh sphere = test::icosphere(1.0, 1);
  CpuCoverageCertifier certifier(sphere);
  const std::vector<Eigen::Vector3f> nan = {{0, 0, 1}, {std::nanf(""), 0, 0}};
  EXPECT_THROW(certifier.certify(nan, 0.5), InputError);
  TriangleMesh broken = sphere;
  broken.vertices[3].x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(CpuCoverageCertifier rejected(broken), InputError);
}

}  // namespace
}  // namespace ts::sampler
