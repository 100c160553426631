// The coverage certificate (sampler/gpu_coverage_certificate.h) on cases whose covering radius is known:
// analytically (a lattice with a particle removed, a plate covered from one side), from the geometry
// (an icosahedral set on a sphere: the exact maximum of the nearest-centre distance over each
// triangle, from its Voronoi vertices), and against dense random sampling. The bound must never be
// below the exact value (nor below any sampled one) and must lie within the stated tolerance above
// it: max(r, c) / 64 (the floor) plus the float margin. The known-answer cases run against both
// certifiers, the GPU one and its CPU twin (sampler/cpu_coverage_certificate.h), so each proves both.
#include "sampler/gpu_coverage_certificate.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <ostream>
#include <random>

#include "core/error.h"
#include "sampler/cpu_coverage_certificate.h"
#include "sampler/point_grid.h"
#include "sampler/sampling_quality.h"
#include "tests/test_meshes.h"

namespace ts::sampler {
namespace {

gpu::Context& shared_context() {
  static gpu::Context context;
  return context;
}

enum class Backend { Gpu, Cpu };
void PrintTo(Backend backend, std::ostream* out) { *out << (backend == Backend::Gpu ? "Gpu" : "Cpu"); }

// Either certifier behind one call.
class EitherCertifier {
 public:
  EitherCertifier(Backend backend, const TriangleMesh& mesh) {
    if (backend == Backend::Gpu) {
      gpu_ = std::make_unique<GpuCoverageCertifier>(shared_context(), mesh);
    } else {
      cpu_ = std::make_unique<CpuCoverageCertifier>(mesh);
    }
  }
  CoverageCertificate certify(std::span<const Eigen::Vector3f> centres, double radius,
                              const CertificateSettings& settings = {}) {
    return gpu_ ? gpu_->certify(centres, radius, settings) : cpu_->certify(centres, radius, settings);
  }

 private:
  std::unique_ptr<GpuCoverageCertifier> gpu_;
  std::unique_ptr<CpuCoverageCertifier> cpu_;
};

// The known-answer cases, each run against both certifiers.
class KnownCoverage : public testing::TestWithParam<Backend> {
 protected:
  EitherCertifier make_certifier(const TriangleMesh& mesh) const { return EitherCertifier(GetParam(), mesh); }
};

std::string backend_name(const testing::TestParamInfo<Backend>& param) {
  return param.param == Backend::Gpu ? "Gpu" : "Cpu";
}

INSTANTIATE_TEST_SUITE_P(Certifiers, KnownCoverage, testing::Values(Backend::Gpu, Backend::Cpu),
                         backend_name);

std::vector<Eigen::Vector3f> to_float(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : points) out.push_back(p.cast<float>());
  return out;
}

std::vector<Eigen::Vector3d> to_double(const std::vector<Eigen::Vector3f>& points) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : points) out.push_back(p.cast<double>());
  return out;
}

// ---------------------------------------------------------------------------------------------
// The exact covering radius of a small set: max over the mesh of the distance to the nearest centre.
// On a triangle that maximum sits at a corner, where an edge crosses the bisector plane of two
// centres, or where the triangle's plane meets the line equidistant from three (a local maximum of
// a minimum of convex functions is never where only one is active, nor inside an edge or the
// triangle where only two are). Only centres that can be nearest somewhere on the triangle count:
// those within U + rho of its centroid (U: smallest largest-corner distance, rho: centroid to corners).

double nearest_distance(const Eigen::Vector3d& x, const std::vector<Eigen::Vector3d>& centres,
                        const std::vector<std::size_t>& among) {
  double best = std::numeric_limits<double>::infinity();
  for (const std::size_t j : among) best = std::min(best, (x - centres[j]).norm());
  return best;
}

std::vector<Eigen::Vector3d> candidate_points(const Eigen::Vector3d (&v)[3],
                                              const std::vector<Eigen::Vector3d>& p,
                                              const std::vector<std::size_t>& near) {
  std::vector<Eigen::Vector3d> out(v, v + 3);
  for (std::size_t a = 0; a < near.size(); ++a)
    for (std::size_t b = a + 1; b < near.size(); ++b) {
      const Eigen::Vector3d d = p[near[b]] - p[near[a]];
      const double rhs = 0.5 * (p[near[b]].squaredNorm() - p[near[a]].squaredNorm());
      for (int e = 0; e < 3; ++e) {  // x = v_e + t (v_e+1 - v_e) with x . d = rhs
        const Eigen::Vector3d o = v[e], dir = v[(e + 1) % 3] - v[e];
        const double den = dir.dot(d);
        if (std::abs(den) < 1e-300) continue;
        const double t = (rhs - o.dot(d)) / den;
        if (t >= 0.0 && t <= 1.0) out.push_back(o + t * dir);
      }
    }
  const Eigen::Vector3d n = (v[1] - v[0]).cross(v[2] - v[0]);
  for (std::size_t a = 0; a < near.size(); ++a)
    for (std::size_t b = a + 1; b < near.size(); ++b)
      for (std::size_t c = b + 1; c < near.size(); ++c) {
        Eigen::Matrix3d m;
        m.row(0) = p[near[b]] - p[near[a]];
        m.row(1) = p[near[c]] - p[near[a]];
        m.row(2) = n;
        const Eigen::Vector3d rhs(0.5 * (p[near[b]].squaredNorm() - p[near[a]].squaredNorm()),
                                  0.5 * (p[near[c]].squaredNorm() - p[near[a]].squaredNorm()), n.dot(v[0]));
        if (std::abs(m.determinant()) < 1e-14 * m.norm() * m.norm() * m.norm()) continue;
        const Eigen::Vector3d x = m.partialPivLu().solve(rhs);
        // Inside the triangle: all three sub-areas on the side of n.
        bool inside = true;
        for (int e = 0; e < 3; ++e)
          inside = inside && (v[(e + 1) % 3] - v[e]).cross(x - v[e]).dot(n) >= -1e-12 * n.squaredNorm();
        if (inside) out.push_back(x);
      }
  return out;
}

double exact_covering_radius(const TriangleMesh& mesh, const std::vector<Eigen::Vector3d>& centres) {
  std::vector<std::size_t> all(centres.size());
  for (std::size_t j = 0; j < all.size(); ++j) all[j] = j;
  double c = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d v[3] = {mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]};
    const Eigen::Vector3d g = (v[0] + v[1] + v[2]) / 3.0;
    double u = std::numeric_limits<double>::infinity(), rho = 0.0;
    for (const auto& p : centres)
      u = std::min(u, std::max({(v[0] - p).norm(), (v[1] - p).norm(), (v[2] - p).norm()}));
    for (const auto& corner : v) rho = std::max(rho, (corner - g).norm());
    std::vector<std::size_t> near;
    for (std::size_t j = 0; j < centres.size(); ++j)
      if ((centres[j] - g).norm() <= u + rho + 1e-12) near.push_back(j);
    for (const Eigen::Vector3d& x : candidate_points(v, centres, near))
      c = std::max(c, nearest_distance(x, centres, near));
  }
  return c;
}

// ---------------------------------------------------------------------------------------------
// Shared checks

// c <= bound <= c + max(r, c) / 64 + margin, lower <= c, and the verdict agrees with c against r
// (when c is not within the tolerance of r, where either verdict is honest).
void expect_bounds_exact(const CoverageCertificate& cert, double exact, double r) {
  const double tolerance = std::max(r, exact) / 64.0 + cert.margin * 1.01;
  EXPECT_GE(cert.covering_bound, exact);
  EXPECT_LE(cert.covering_bound, exact + tolerance);
  EXPECT_LE(cert.covering_lower, exact * (1.0 + 1e-9));
  EXPECT_EQ(cert.uncovered == 0, cert.covered);
  EXPECT_EQ(cert.covered, cert.covering_bound <= r);
  if (exact + tolerance < r) {
    EXPECT_TRUE(cert.covered);
  }
  if (exact > r) {
    EXPECT_FALSE(cert.covered);
  }
  std::printf(
      "  r %.6g: c exact %.6g, bound %.6g (+%.2e), lower %.6g, %zu of %zu sub-triangles uncovered, %d "
      "levels\n",
      r, exact, cert.covering_bound, cert.covering_bound - exact, cert.covering_lower, cert.uncovered,
      cert.evaluated, cert.levels);
}

// Hexagonal lattice of spacing s over [x0, x1] x [y0, y1] (a point at the origin), at height z.
std::vector<Eigen::Vector3d> hex_lattice(double s, double x0, double x1, double y0, double y1, double z) {
  const double h = s * std::sqrt(3.0) / 2.0;
  std::vector<Eigen::Vector3d> points;
  for (int j = static_cast<int>(std::floor(y0 / h)); j * h <= y1; ++j)
    for (int i = static_cast<int>(std::floor(x0 / s)) - 1; (i + 0.5 * std::abs(j % 2)) * s <= x1; ++i)
      points.emplace_back(s * (i + 0.5 * std::abs(j % 2)), h * j, z);
  return points;
}

// A square patch [0, a]^2 at z = 0 as an n x n grid of quads, two triangles each.
TriangleMesh square_patch(double a, int n) {
  TriangleMesh mesh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.vertices.emplace_back(a * i / n, a * j / n, 0.0);
  auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return mesh;
}

// ---------------------------------------------------------------------------------------------

TEST_P(KnownCoverage, IcosahedralSetsOnASphereAreBoundedWithinTheFloorOfTheirExactCoveringRadius) {
  const TriangleMesh sphere = test::icosphere(1.0, 4);  // 5120 triangles, vertices on the unit sphere
  // The 12 icosahedron vertices and the 42 of its first geodesic subdivision are its first vertices.
  for (const std::size_t n : {std::size_t{12}, std::size_t{42}}) {
    const std::vector<Eigen::Vector3d> centres(sphere.vertices.begin(), sphere.vertices.begin() + n);
    const double exact = exact_covering_radius(sphere, centres);
    if (n == 12) {
      // On the true sphere the deepest points are the face centres, at the angle theta from the
      // vertices with cos theta = sqrt((5 + 2 sqrt 5) / 15): chord sqrt(2 - 2 cos theta) = 0.6408.
      // The mesh lies inside the sphere, by at most its sagitta (1 - cos of half an edge's angle).
      const double chord = std::sqrt(2.0 - 2.0 * std::sqrt((5.0 + 2.0 * std::sqrt(5.0)) / 15.0));
      const double edge_angle =
          std::acos(sphere.vertices[sphere.triangles[0][0]].dot(sphere.vertices[sphere.triangles[0][1]]));
      EXPECT_NEAR(exact, chord, 1.0 - std::cos(0.5 * edge_angle));
    }
    EitherCertifier certifier = make_certifier(sphere);
    const std::vector<Eigen::Vector3f> stored = to_float(centres);
    for (const double r : {1.1 * exact, 0.97 * exact}) {
      const CoverageCertificate cert = certifier.certify(stored, r);
      expect_bounds_exact(cert, exact, r);
      if (n == 12 && r < exact) {
        // The holes are the 20 face centres of the icosahedron, one point each.
        const std::vector<UncoveredPiece> holes = deepest_holes(cert, stored, 100);
        EXPECT_EQ(holes.size(), 20u);
        for (const auto& h : holes) EXPECT_NEAR(h.depth, exact, exact / 16.0);
      }
    }
  }
}

TEST_P(KnownCoverage, LatticeWithOneParticleRemovedHasAHoleAsDeepAsTheSpacing) {
  const double s = 0.05;
  const TriangleMesh patch = square_patch(1.0, 3);
  std::vector<Eigen::Vector3d> lattice = hex_lattice(s, -2 * s, 1.0 + 2 * s, -2 * s, 1.0 + 2 * s, 0.0);
  EitherCertifier certifier = make_certifier(patch);
  const double r = 0.75 * s;  // above the lattice's s / sqrt(3), below the hole's s
  {
    const CoverageCertificate full = certifier.certify(to_float(lattice), r);
    expect_bounds_exact(full, s / std::sqrt(3.0), r);
  }
  // Remove the lattice point nearest (0.5, 0.5): its six neighbours at s leave a hole s deep there.
  const auto removed = std::min_element(lattice.begin(), lattice.end(), [](const auto& a, const auto& b) {
    return (a - Eigen::Vector3d(0.5, 0.5, 0)).norm() < (b - Eigen::Vector3d(0.5, 0.5, 0)).norm();
  });
  const Eigen::Vector3d q = *removed;
  lattice.erase(removed);
  const CoverageCertificate cert = certifier.certify(to_float(lattice), r);
  expect_bounds_exact(cert, s, r);
  EXPECT_GE(cert.covering_lower, s * (1.0 - 1.0 / 16.0));
  // Everything uncovered lies in the hole: points farther than r from the neighbours, within s - r of
  // q towards a neighbour and sqrt(r^2 - (s/2)^2) ... at most s - r + a floor piece beyond.
  for (const UncoveredPiece& p : cert.pieces)
    EXPECT_LT((p.position - q).norm(), s - r + 0.5 * s) << p.position.transpose();
  const std::vector<UncoveredPiece> holes = deepest_holes(cert, to_float(lattice), 10);
  ASSERT_EQ(holes.size(), 1u);
  EXPECT_LT((holes[0].position - q).norm(), r / 16.0);
  // The uncovered region holds the disc of radius s - r about q; the certificate's area is an upper bound.
  EXPECT_GE(cert.uncovered_area, M_PI * (s - r) * (s - r));
  EXPECT_LE(cert.uncovered_area, M_PI * s * s);
}

// A triangle larger than the neighbour search: its corners lie beyond the shells searched from its
// centroid although centres are near it (for the CPU certifier, whose search has no shell limit, a
// triangle many radii across). An equilateral triangle whose circumcentre O is a hole of
// a hexagonal lattice (distance s / sqrt 3 from the nearest lattice points) has, for every centre p,
// a corner at least sqrt(rho^2 + |p - O|^2) from p (its corner vectors from O sum to zero): with rho
// just below the search radius the smallest largest-corner distance lies beyond it. The triangle
// must still be split and certified: c = s / sqrt 3 (O is in it; no point of the plane is deeper).
TEST_P(KnownCoverage, TriangleLargerThanTheSearchIsSplitAndCertified) {
  const double s = 0.05, r = 0.75 * s, hole = s / std::sqrt(3.0);
  const Eigen::Vector3d o(0.5 * s, 0.5 * s / std::sqrt(3.0), 0.0);  // centroid of (0,0), (s,0), (s/2, h)
  for (const int shells : {2, 8}) {
    const double rho = (shells - 0.02) * r;                     // below the search radius shells * r ...
    ASSERT_GT(std::sqrt(rho * rho + hole * hole), shells * r);  // ... its best corner distance above it
    TriangleMesh triangle;
    for (const double degrees : {90.0, 210.0, 330.0}) {
      const double a = degrees * M_PI / 180.0;
      triangle.vertices.push_back(o + rho * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0));
    }
    triangle.triangles.push_back({0, 1, 2});
    const double reach = rho + 2.0 * s;
    const std::vector<Eigen::Vector3d> lattice =
        hex_lattice(s, o.x() - reach, o.x() + reach, o.y() - reach, o.y() + reach, 0.0);
    EitherCertifier certifier = make_certifier(triangle);
    CertificateSettings settings;
    settings.max_shells = shells;
    const CoverageCertificate cert = certifier.certify(to_float(lattice), r, settings);
    expect_bounds_exact(cert, hole, r);
    EXPECT_TRUE(cert.covered) << shells << " shells";
  }
}

// A plate with particles over its top face only: each face is judged on its own. A point of the
// bottom face lies sqrt(t^2 + d^2) from a top particle (d: in-plane distance), so the covering
// radius is sqrt(t^2 + s^2 / 3), on the bottom face. Thin (t = 0.3 s): the top balls reach through and
// the certificate holds. Thick (t = 2 s): the whole bottom face and the lower sides are uncovered, and
// nothing of the top face is.
TEST_P(KnownCoverage, PlateCoveredFromOneSideIsJudgedFaceByFace) {
  const double s = 0.05, a = 0.5, r = 0.75 * s;
  for (const double t : {0.3 * s, 2.0 * s}) {
    const TriangleMesh plate = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(a, a, t));
    const std::vector<Eigen::Vector3d> top = hex_lattice(s, -2 * s, a + 2 * s, -2 * s, a + 2 * s, t);
    const double exact = std::sqrt(t * t + s * s / 3.0);
    EitherCertifier certifier = make_certifier(plate);
    const CoverageCertificate cert = certifier.certify(to_float(top), r);
    expect_bounds_exact(cert, exact, r);
    if (t < r) continue;
    double bottom_area = 0.0;
    for (const UncoveredPiece& p : cert.pieces) {
      EXPECT_LT(p.position.z(), t - 0.5 * r) << "a piece of the top face or its rim is reported uncovered";
      if (p.normal.z() < -0.5) bottom_area += p.area;
    }
    EXPECT_NEAR(bottom_area, a * a, 1e-9 * a * a);  // all of the far face, none of it certified
    EXPECT_LE(cert.uncovered_area, a * a + 4.0 * a * t);
    // With a search too short to find any top particle from the bottom face, the GPU's pieces are
    // bounded on the CPU: still above the exact value, and still uncovered. (The CPU certifier's
    // search is exact whatever max_shells says; the same statements hold for it.)
    CertificateSettings short_search;
    short_search.max_shells = 1;
    const CoverageCertificate shortened = certifier.certify(to_float(top), r, short_search);
    EXPECT_GE(shortened.covering_bound, exact);
    EXPECT_LE(shortened.covering_lower, exact);
    EXPECT_FALSE(shortened.covered);
    EXPECT_GE(shortened.uncovered_area, a * a * (1.0 - 1e-9));
  }
}

TEST_P(KnownCoverage, NeverBelowDenseSamplingNorTheExactValueOnARandomSet) {
  const TriangleMesh sphere = test::icosphere(1.0, 3);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Vector3d> centres;
  for (int i = 0; i < 60; ++i)
    centres.push_back(Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized());
  const std::vector<Eigen::Vector3f> stored = to_float(centres);
  const std::vector<Eigen::Vector3d> as_stored = to_double(stored);
  const double exact = exact_covering_radius(sphere, as_stored);
  // Dense sampling: two million area-uniform points and every vertex.
  CoverageSettings dense;
  dense.probes = 2'000'000;
  dense.seed = 11;
  double sampled = measure_coverage(sphere, as_stored, dense).covering_radius;
  const PointGrid grid(as_stored, 0.3);
  for (const auto& v : sphere.vertices) sampled = std::max(sampled, grid.nearest(v).distance);
  EXPECT_LE(sampled, exact * (1.0 + 1e-12));
  EXPECT_GT(sampled, 0.98 * exact);
  EitherCertifier certifier = make_certifier(sphere);
  for (const double r : {0.8 * exact, 1.05 * exact}) {
    const CoverageCertificate cert = certifier.certify(stored, r);
    EXPECT_GE(cert.covering_bound, sampled);
    expect_bounds_exact(cert, exact, r);
  }
}

TEST(CoverageCertificate, SameInputGivesTheSameBitsAndABudgetCostsTilesNotRefinement) {
  const TriangleMesh sphere = test::icosphere(1.0, 3);
  const std::vector<Eigen::Vector3d> centres(sphere.vertices.begin(), sphere.vertices.begin() + 42);
  const std::vector<Eigen::Vector3f> stored = to_float(centres);
  GpuCoverageCertifier certifier(shared_context(), sphere);
  const CoverageCertificate a = certifier.certify(stored, 0.3);
  const CoverageCertificate b = certifier.certify(stored, 0.3);
  EXPECT_EQ(a.covering_bound, b.covering_bound);
  EXPECT_EQ(a.covering_lower, b.covering_lower);
  EXPECT_EQ(a.evaluated, b.evaluated);
  ASSERT_EQ(a.pieces.size(), b.pieces.size());
  ASSERT_GT(a.pieces.size(), 0u);
  for (std::size_t k = 0; k < a.pieces.size(); ++k) {
    EXPECT_EQ(a.pieces[k].position, b.pieces[k].position);
    EXPECT_EQ(a.pieces[k].bound, b.pieces[k].bound);
  }
  // A level budget smaller than the work splits the triangles into tiles, each certified to the
  // floor: the verdict of the unlimited run, bounds as tight to within the floor, nothing coarser.
  const double exact = exact_covering_radius(sphere, to_double(stored));
  CertificateSettings tight;
  tight.max_subtriangles = 5000;
  for (const double r : {0.3, 1.2 * exact}) {
    const CoverageCertificate whole = certifier.certify(stored, r);
    const CoverageCertificate tiled = certifier.certify(stored, r, tight);
    EXPECT_EQ(whole.tiles, 1u);
    EXPECT_GT(tiled.tiles, 1u);
    EXPECT_GE(tiled.tiles_redone, 1u);
    EXPECT_FALSE(tiled.budget_reached);
    EXPECT_EQ(tiled.covered, whole.covered);
    EXPECT_GE(tiled.covering_bound, exact);
    EXPECT_LE(tiled.covering_lower, exact);
    EXPECT_LE(tiled.covering_bound, exact + std::max(r, exact) / tight.floor_divisor + 1e-6);
    EXPECT_EQ(tiled.covered, tiled.covering_bound <= r);
  }
  // A budget even one triangle passes makes that triangle's level final: coarser, never optimistic.
  CertificateSettings starved;
  starved.max_subtriangles = 3;
  for (const double r : {0.3, 1.2 * exact}) {
    const CoverageCertificate budget = certifier.certify(stored, r, starved);
    EXPECT_TRUE(budget.budget_reached);
    EXPECT_EQ(budget.tiles, sphere.triangle_count());
    EXPECT_GE(budget.covering_bound, exact);
    EXPECT_LE(budget.covering_lower, exact);
    EXPECT_EQ(budget.covered, budget.covering_bound <= r);
  }
}

TEST(CoverageCertificate, LevelBudgetIsBoundedOnlyByItsThirtyTwoBitCounts) {
  // Levels of any size go out as a 2D grid of work groups, so a budget past the old one-row limit
  // (16M) is taken and changes nothing where the work is small; one whose children (four per
  // sub-triangle) could not count in 32 bits is refused.
  const TriangleMesh sphere = test::icosphere(1.0, 2);
  const std::vector<Eigen::Vector3f> stored =
      to_float(std::vector<Eigen::Vector3d>(sphere.vertices.begin(), sphere.vertices.begin() + 42));
  GpuCoverageCertifier certifier(shared_context(), sphere);
  CertificateSettings large;
  large.max_subtriangles = std::size_t{1} << 28;
  const CoverageCertificate by_default = certifier.certify(stored, 0.3);
  const CoverageCertificate with_large = certifier.certify(stored, 0.3, large);
  EXPECT_EQ(with_large.covering_bound, by_default.covering_bound);
  EXPECT_EQ(with_large.evaluated, by_default.evaluated);
  CertificateSettings too_large;
  too_large.max_subtriangles = std::size_t{1} << 30;
  EXPECT_THROW(certifier.certify(stored, 0.3, too_large), Error);
}

TEST_P(KnownCoverage, FarFromTheOriginAndTinyTheBoundStaysAboveTheExactValue) {
  // The lattice-with-a-hole case, 1000 times smaller and 20 m from the origin: the float margin
  // grows with the distance from the mesh's own centre only, not from the origin.
  const double s = 0.05e-3, r = 0.75 * s;
  TriangleMesh patch = square_patch(1e-3, 16);  // small triangles keep the exact oracle quick
  const Eigen::Vector3d offset(10.0, -20.0, 5.0);
  for (auto& v : patch.vertices) v += offset;
  std::vector<Eigen::Vector3d> lattice = hex_lattice(s, -2 * s, 1e-3 + 2 * s, -2 * s, 1e-3 + 2 * s, 0.0);
  std::erase_if(lattice, [&](const Eigen::Vector3d& p) {
    return (p - Eigen::Vector3d(0.5e-3, 0.5e-3, 0)).norm() < 0.5 * s;
  });
  std::vector<Eigen::Vector3f> stored;
  for (const auto& p : lattice) stored.push_back((p + offset).cast<float>());
  // The exact value of the particles as stored (float positions 20 m out are 2e-6 m apart).
  std::vector<Eigen::Vector3d> as_stored = to_double(stored);
  const double exact = exact_covering_radius(patch, as_stored);
  EXPECT_NEAR(exact, s, 0.2 * s);
  EitherCertifier certifier = make_certifier(patch);
  const CoverageCertificate cert = certifier.certify(stored, r);
  EXPECT_GE(cert.covering_bound, exact);
  EXPECT_LE(cert.covering_lower, exact);
  EXPECT_FALSE(cert.covered);
  std::printf("  offset: c exact %.6g, bound %.6g, margin %.2e\n", exact, cert.covering_bound, cert.margin);
}

}  // namespace
}  // namespace ts::sampler
