// The whole sampler (tetrasand sample's pipeline) against the quality figures of the sample issue,
// measured independently of what the sampler reports: relative radius rho >= 0.7, CV of nearest-
// neighbour distances <= 0.1, covering radius c <= r over a million area-uniform probes, largest
// |phi| <= 0.05 r, particle count within 10 % of the area estimate, mass properties equal to the
// mesh's. Counts are small (300-900) so the set stays within a few minutes on llvmpipe.
#include "sampler/sample_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/mass_properties.h"
#include "core/mesh_io.h"
#include "sampler/point_grid.h"
#include "sampler/sampling_quality.h"
#include "sdf/exact_sdf.h"
#include "tests/test_support.h"

namespace ts::sampler {
namespace {

gpu::Context& shared_context() {
  static gpu::Context context;
  return context;
}

struct Case {
  std::string name;  // assets/NAME.obj, or cgal:NAME for libcgal-demo's data/meshes/NAME.off
  std::size_t count;
};

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string n = info.param.name;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n + "_" + std::to_string(info.param.count);
}

TriangleMesh load_case(const std::string& name) {
  if (name.rfind("cgal:", 0) == 0) return load_mesh(test::cgal_mesh(name.substr(5)));
  return load_mesh(test::asset(name + ".obj"));
}

void expect_meets_quality_targets(const TriangleMesh& mesh, const SampleResult& result, double density) {
  const body::ParticleBody& body = result.body;
  const double r = body.particle_radius;
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : body.positions) points.push_back(p.cast<double>());
  CoverageSettings probes;
  probes.probes = 1'000'000;
  probes.seed = 777;  // not one the sampler used
  const SamplingQuality q = measure_quality(mesh, points, r, probes);

  // The certificate: never below any probe (the sampler's own or these independent ones). Every body
  // here is certified after the rounds (the holes are printed if one is not), so no probe lies deeper
  // than r. The figures are printed for the record.
  ASSERT_TRUE(body.quality.certificate.has_value());
  const auto& cert = *body.quality.certificate;
  EXPECT_GE(cert.bound_over_r, body.quality.covering_over_r);
  EXPECT_GE(cert.bound_over_r, q.covering_over_r);
  EXPECT_TRUE(cert.certified);
  EXPECT_EQ(cert.uncovered_subtriangles, 0u);
  EXPECT_LE(cert.bound_over_r, 1.0);
  EXPECT_LE(q.covering_over_r, 1.0);
  std::printf(
      "  %zu particles: certificate %s, c / r in [%.4f, %.4f], %zu sub-triangles uncovered (%.3g m^2); "
      "probes: own %.4f, independent %.4f; %d rounds\n",
      q.count, cert.certified ? "holds" : "FAILS", cert.lower_over_r, cert.bound_over_r,
      cert.uncovered_subtriangles, cert.uncovered_area, body.quality.covering_over_r, q.covering_over_r,
      body.quality.injection_rounds);
  for (const auto& h : result.holes) {
    std::printf("    hole %.4f r at (%.5g, %.5g, %.5g)\n", h.depth / r, h.position.x(), h.position.y(),
                h.position.z());
  }

  EXPECT_GE(q.relative_radius, 0.7);
  EXPECT_LE(q.cv_nn, 0.1);
  EXPECT_LE(body.quality.covering_over_r, 1.0);  // the sampler's own 1M-probe pass
  EXPECT_LE(q.max_abs_phi / r, 0.05);
  EXPECT_NEAR(static_cast<double>(q.count), static_cast<double>(result.estimated_count),
              0.1 * static_cast<double>(result.estimated_count));
  EXPECT_TRUE(body.quality.converged);
  // The reported figures are the measured ones.
  EXPECT_NEAR(body.quality.relative_radius, q.relative_radius, 1e-6);
  EXPECT_NEAR(body.quality.cv, q.cv_nn, 1e-6);

  const MassProperties m = compute_mass_properties(mesh, density);
  EXPECT_NEAR(body.mass, m.mass, 1e-9 * m.mass);
  EXPECT_NEAR(body.volume, m.volume, 1e-9 * m.volume);
  const double size = std::cbrt(m.volume);
  EXPECT_LE((body.center_of_mass - m.center_of_mass).norm(), 1e-9 * size);
  EXPECT_LE((body.inertia - m.inertia).norm(), 1e-9 * m.inertia.norm());
}

class SampleQuality : public ::testing::TestWithParam<Case> {};

TEST_P(SampleQuality, MeetsEveryTargetOfTheIssue) {
  const TriangleMesh mesh = load_case(GetParam().name);
  SampleSettings settings;
  settings.count = GetParam().count;
  settings.density = 1250.0;
  const SampleResult result = sample_mesh(shared_context(), mesh, settings);
  expect_meets_quality_targets(mesh, result, settings.density);
}

// Generated assets (the plate is 2 mm thick: only far finer radii than a test can afford resolve it;
// the bunny's ears are thinner than the voxel at these counts; both are reported as thin features;
// the cube at 300 particles does not converge: particles on the rounded corners of the field ring).
INSTANTIATE_TEST_SUITE_P(Assets, SampleQuality,
                         ::testing::Values(Case{"sphere", 300}, Case{"sphere", 700}, Case{"cube", 500},
                                           Case{"cube", 700}, Case{"torus", 300}, Case{"torus", 700},
                                           Case{"trefoil", 400}, Case{"trefoil", 700}),
                         case_name);

// Real closed meshes from libcgal-demo, two radii each. Not here, because they miss a target at counts a
// test can afford (see docs/benchmarks.md): elephant, fandisk, bunny00 (features thinner than the
// spacing), joint and handle (holes left at sharp creases after the round limit).
INSTANTIATE_TEST_SUITE_P(CgalMeshes, SampleQuality,
                         ::testing::Values(Case{"cgal:knot1", 400}, Case{"cgal:knot1", 700}, Case{"cgal:eight", 400},
                                           Case{"cgal:eight", 700}, Case{"cgal:blobby", 400}, Case{"cgal:blobby", 700},
                                           Case{"cgal:cactus", 400}, Case{"cgal:cactus", 600},
                                           Case{"cgal:bear", 300}, Case{"cgal:bear", 500}),
                         case_name);

// Evenness on a real mesh with thin features (libcgal-demo's triceratops: 1.2 % of its area thinner
// than the spacing at these counts), where rho, the closest pair over d_hex, is decided by one pair and
// so by the seed: issue 43's fall at one seed was such a draw (docs/benchmarks/sampler.md, "Evenness on
// triceratops"). Over three seeds the median must stay at 0.70 or above and no seed may fall to the
// crowded-pair floor (0.6 spacing): 7fd726d's sampler, on the hardware-filtered dense field, gave
// 0.608, 0.617 and 0.611 here; today's 0.725, 0.743, 0.748. CPU path, no GL context: seconds.
TEST(SampleMesh, EvennessOnAThinFeaturedCgalMeshHoldsAcrossSeeds) {
  const TriangleMesh mesh = load_mesh(test::cgal_mesh("triceratops"));
  const double area = surface_area(mesh);
  std::vector<double> rhos;
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SampleSettings settings;
    settings.count = 4000;
    settings.seed = seed;
    settings.probes = 100'000;  // the statistical figure only; rho does not depend on it
    settings.backend = gpu::Backend::Cpu;
    const SampleResult result = sample_mesh(nullptr, mesh, settings);
    std::vector<Eigen::Vector3d> points;
    for (const auto& p : result.body.positions) points.push_back(p.cast<double>());
    const SpacingStatistics spacing = spacing_statistics(area, points);  // measured here, not reported
    std::printf("  seed %llu: rho %.4f, CV %.4f, %d iterations\n", static_cast<unsigned long long>(seed),
                spacing.relative_radius, spacing.cv_nn, result.body.quality.iterations);
    EXPECT_GE(spacing.relative_radius, 0.6) << "seed " << seed;
    EXPECT_LE(spacing.cv_nn, 0.05) << "seed " << seed;
    rhos.push_back(spacing.relative_radius);
  }
  std::sort(rhos.begin(), rhos.end());
  EXPECT_GE(rhos[1], 0.70);  // the median
}

// An open mesh under winding-number signs: elephant-with-holes is the closed elephant with 106
// holes cut. Its particles must sit on its surface, their normals point out of the closed elephant,
// and its mass properties (winding-number solid) be close to the closed elephant's (tolerances as
// measured in winding_solid_test.cpp: volume 1.1 %, centre 0.16 %, inertia 1.8 %).
TEST(SampleMesh, OpenMeshWithWindingSignsStaysOnTheSurfaceWithTheClosedMassProperties) {
  const TriangleMesh open = load_mesh(test::cgal_mesh("elephant-with-holes"));
  const TriangleMesh closed = load_mesh(test::cgal_mesh("elephant"));
  SampleSettings settings;
  settings.count = 300;
  settings.probes = 200'000;
  settings.sign = sdf::SignMethod::Winding;
  settings.mass_method = body::MassMethod::WindingCells;
  const SampleResult result = sample_mesh(shared_context(), open, settings);
  const body::ParticleBody& body = result.body;
  const double r = body.particle_radius;
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : body.positions) points.push_back(p.cast<double>());
  EXPECT_LE(max_distance_to_surface(open, points) / r, 0.05);
  // (No count target: the rims of 106 holes, covered from one side only, take 13 % more particles
  // than the area estimate at this count.)

  const sdf::ExactDistance truth(closed);
  std::size_t outward = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    outward += truth.feature_normal(truth.closest(points[i])).dot(body.normals[i].cast<double>()) > 0.0 ? 1 : 0;
  }
  EXPECT_GE(static_cast<double>(outward), 0.99 * static_cast<double>(points.size()));

  EXPECT_EQ(body.mass_method, body::MassMethod::WindingCells);
  EXPECT_GT(body.mass_cell, 0.0);
  const MassProperties m = compute_mass_properties(closed, settings.density);
  EXPECT_NEAR(body.volume, m.volume, 0.015 * m.volume);
  EXPECT_LE((body.center_of_mass - m.center_of_mass).norm(), 0.003 * std::cbrt(m.volume));
  EXPECT_LE((body.inertia - m.inertia).norm(), 0.025 * m.inertia.norm());
  EXPECT_DOUBLE_EQ(body.mass, settings.density * body.volume);
}

// --fill: interior particles on the FCC lattice of spacing 2 r (sampler/interior_fill.h), kept where
// phi <= -r. Checked independently: none outside or closer than r to the surface, none closer than
// r to a surface particle, none closer than 2 r to each other, zero normals, and the count.
void expect_a_valid_fill(const TriangleMesh& mesh, const SampleResult& result) {
  const body::ParticleBody& body = result.body;
  const double r = body.particle_radius;
  const std::size_t surface = body.positions.size() - body.interior_count;
  ASSERT_GT(body.interior_count, 0u);
  std::vector<Eigen::Vector3d> outer, inner;
  for (std::size_t i = 0; i < body.positions.size(); ++i) {
    (i < surface ? outer : inner).push_back(body.positions[i].cast<double>());
    if (i < surface) {
      EXPECT_NEAR(body.normals[i].norm(), 1.0f, 1e-4f) << i;
    } else {
      EXPECT_EQ(body.normals[i], Eigen::Vector3f::Zero()) << i;
    }
  }
  const sdf::ExactDistance exact(mesh);
  const PointGrid surface_grid(outer, r), inner_grid(inner, 2.0 * r);
  double deepest_shallow = -1e300, nearest_surface = 1e300, nearest_inner = 1e300;
  for (std::size_t i = 0; i < inner.size(); ++i) {
    deepest_shallow = std::max(deepest_shallow, exact.signed_distance(inner[i], sdf::SignMethod::Pseudonormal) / r);
    nearest_surface = std::min(nearest_surface, surface_grid.nearest(inner[i]).distance / r);
    nearest_inner = std::min(nearest_inner, inner_grid.nearest(inner[i], i).distance / r);
  }
  EXPECT_LE(deepest_shallow, -1.0 + 1e-6);  // float positions: phi <= -r up to rounding
  EXPECT_GE(nearest_surface, 1.0 - 1e-5);
  EXPECT_NEAR(nearest_inner, 2.0, 1e-5);
}

TEST(SampleMesh, FillPutsInteriorParticlesOnALatticeInsideTheSphere) {
  const TriangleMesh mesh = load_mesh(test::asset("sphere.obj"));
  SampleSettings settings;
  settings.count = 600;
  settings.probes = 200'000;
  settings.fill = true;
  const SampleResult result = sample_mesh(shared_context(), mesh, settings);
  expect_a_valid_fill(mesh, result);
  // Lattice estimate of the inner ball of radius R - r (R from the mesh's volume).
  const double r = result.body.particle_radius;
  const double big = std::cbrt(3.0 * compute_mass_properties(mesh, 1.0).volume / (4.0 * std::numbers::pi));
  const double estimate =
      4.0 / 3.0 * std::numbers::pi * std::pow(big - r, 3) / (4.0 * std::sqrt(2.0) * r * r * r);
  std::printf("sphere: %zu interior particles, ball estimate %.1f, V - A r estimate %.1f\n", result.body.interior_count,
              estimate, result.estimated_interior);
  EXPECT_NEAR(static_cast<double>(result.body.interior_count), estimate, 0.05 * estimate);
  EXPECT_NEAR(result.estimated_interior, estimate, 0.15 * estimate);
  // The quality figures are of the surface layer alone.
  EXPECT_GE(result.body.quality.relative_radius, 0.7);
}

TEST(SampleMesh, FillOfTheCubeHoldsExactlyTheLatticePointsOfTheInnerCube) {
  const TriangleMesh mesh = load_mesh(test::asset("cube.obj"));  // side 0.1 m, centred at 0
  SampleSettings settings;
  settings.count = 1500;
  settings.probes = 200'000;
  settings.fill = true;
  const SampleResult result = sample_mesh(shared_context(), mesh, settings);
  expect_a_valid_fill(mesh, result);
  // FCC points (i, j, k) * a / 2 with i + j + k even, a = 2 sqrt(2) r, origin at the centre: those in
  // the inner cube of half-side 0.05 - r.
  const double r = result.body.particle_radius, half_step = std::sqrt(2.0) * r;
  const int m = static_cast<int>(std::floor((0.05 - r) / half_step));
  std::size_t expected = 0;
  for (int i = -m; i <= m; ++i)
    for (int j = -m; j <= m; ++j)
      for (int k = -m; k <= m; ++k) expected += (i + j + k) % 2 == 0 ? 1 : 0;
  std::printf("cube: %zu interior particles, %zu lattice points in the inner cube, V - A r estimate %.1f\n",
              result.body.interior_count, expected, result.estimated_interior);
  EXPECT_EQ(result.body.interior_count, expected);
}

TEST(SampleMesh, IsDeterministicForAFixedSeed) {
  const TriangleMesh mesh = load_mesh(test::asset("torus.obj"));
  SampleSettings settings;
  settings.count = 300;
  settings.probes = 200'000;
  const SampleResult a = sample_mesh(shared_context(), mesh, settings);
  const SampleResult b = sample_mesh(shared_context(), mesh, settings);
  ASSERT_EQ(a.body.positions.size(), b.body.positions.size());
  for (std::size_t i = 0; i < a.body.positions.size(); ++i) ASSERT_EQ(a.body.positions[i], b.body.positions[i]) << i;
  settings.seed = 2;
  const SampleResult c = sample_mesh(shared_context(), mesh, settings);
  EXPECT_NE(a.body.positions.front(), c.body.positions.front());
}

TEST(SampleMesh, TinyAndHugeCopiesOfAMeshGiveTheSameQualityFigures) {
  const TriangleMesh unit = load_mesh(test::asset("torus.obj"));
  std::vector<body::ParticleBody::Quality> figures;
  for (const double factor : {1e-4 / 0.1, 1e4 / 0.1}) {  // the torus is about 0.1 m across
    TriangleMesh mesh = unit;
    scale_mesh(mesh, factor);
    SampleSettings settings;
    settings.count = 400;
    settings.probes = 1'000'000;
    const SampleResult result = sample_mesh(shared_context(), mesh, settings);
    expect_meets_quality_targets(mesh, result, settings.density);
    figures.push_back(result.body.quality);
  }
  EXPECT_NEAR(figures[0].relative_radius, figures[1].relative_radius, 0.05);
  EXPECT_NEAR(figures[0].cv, figures[1].cv, 0.02);
  EXPECT_NEAR(figures[0].covering_over_r, figures[1].covering_over_r, 0.05);
}

TEST(SampleMesh, RadiusLargerThanTheMeshIsRefused) {
  const TriangleMesh mesh = load_mesh(test::asset("sphere.obj"));
  SampleSettings settings;
  settings.radius = 1.0;
  try {
    sample_mesh(shared_context(), mesh, settings);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too large"), std::string::npos) << e.what();
  }
}

TEST(SampleMesh, CountOverTheMemoryCapNamesTheLargestThatFits) {
  const TriangleMesh mesh = load_mesh(test::asset("sphere.obj"));
  SampleSettings settings;
  settings.count = 5000;
  settings.max_particles = 1000;
  try {
    sample_mesh(shared_context(), mesh, settings);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cap of 1000"), std::string::npos) << what;
    EXPECT_NE(what.find("smallest radius that fits"), std::string::npos) << what;
  }
}

TEST(SampleMesh, FillOverTheMemoryCapNamesTheSmallestRadiusThatFits) {
  const TriangleMesh mesh = load_mesh(test::asset("sphere.obj"));
  SampleSettings settings;
  settings.count = 300;
  settings.max_particles = 400;  // the surface fits, the filled body (about 470) does not
  settings.fill = true;
  try {
    sample_mesh(shared_context(), mesh, settings);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cap of 400"), std::string::npos) << what;
    EXPECT_NE(what.find("smallest radius whose filled body fits"), std::string::npos) << what;
  }
}

// The probe pass's size: probes_per_particle per surface particle, at least kMinProbes, at most
// `probes` (docs/coverage-certificate.md, "The probe pass").
TEST(SampleMesh, ProbeCountFollowsTheStatedFormula) {
  SampleSettings s;  // 256 per particle, at least 65536, at most 1M
  EXPECT_EQ(probe_count(10, s), kMinProbes);
  EXPECT_EQ(probe_count(256, s), kMinProbes);
  EXPECT_EQ(probe_count(1002, s), 256u * 1002u);
  EXPECT_EQ(probe_count(3906, s), 256u * 3906u);
  EXPECT_EQ(probe_count(3907, s), 1'000'000u);
  EXPECT_EQ(probe_count(10'000'000'000'000'000ull, s), 1'000'000u);  // no overflow
  s.probes = 20'000;                                                 // the cap wins over the floor
  EXPECT_EQ(probe_count(1000, s), 20'000u);
  s.probes = 5'000'000, s.probes_per_particle = 0;  // 0: always the cap
  EXPECT_EQ(probe_count(10, s), 5'000'000u);
}

// The miss bound of the probe pass, on a case whose covering radius is known: a hexagonal lattice of
// spacing h over a square with one centre removed has c = h (the removed centre's six neighbours).
// Every surface point within delta of the hole's centre lies deeper than c - delta, and that disc
// has area pi delta^2, so probe_count(N) area-uniform probes miss it with probability at most
// exp(-P pi delta^2 / A): delta is chosen so that this bound is 1e-6, and the pass must find the hole
// to within it.
TEST(SampleMesh, ProportionalProbesFindAKnownHoleWithinTheStatedBound) {
  const double side = 1.0, h = 0.05;
  TriangleMesh square;
  square.vertices = {{0, 0, 0}, {side, 0, 0}, {side, side, 0}, {0, side, 0}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  std::vector<Eigen::Vector3d> centres;  // beyond the square too, so its rim has no deeper holes
  const double row = h * std::sqrt(3.0) / 2.0;
  for (int j = -2; j * row <= side + 2 * h; ++j)
    for (int i = -2; i * h <= side + 2 * h; ++i) {
      const Eigen::Vector3d p((i + 0.5 * (j & 1)) * h, j * row, 0.0);
      if ((p - Eigen::Vector3d(0.5 * side, 0.5 * side, 0.0)).norm() < 0.7 * row) continue;  // the hole
      centres.push_back(p);
    }
  const std::size_t n = centres.size();
  const std::size_t probes = probe_count(n, SampleSettings{});
  EXPECT_EQ(probes, std::max(kMinProbes, 256 * n));
  const double delta =
      std::sqrt(std::log(1e6) * side * side / (std::numbers::pi * static_cast<double>(probes)));
  // The removed centre sat at a lattice point near the middle: c = h there.
  for (const std::uint64_t seed : {1ull, 2ull, 3ull}) {
    CoverageSettings c;
    c.probes = probes;
    c.seed = seed;
    const CoverageResult result = measure_coverage(square, centres, c);
    EXPECT_LE(result.covering_radius, h * (1.0 + 1e-9));
    EXPECT_GE(result.covering_radius, h - delta) << "seed " << seed << ", delta " << delta / h << " h";
  }
  EXPECT_LT(delta, 0.15 * h);  // the bound is worth having at this count: 0.1 h
}

// Every SDF path gives a body that meets the targets: the exact CPU field (the default on a software
// renderer for small grids, gpu::Backend::Auto), OpenVDB's on the CPU and the GPU scan conversion; the
// result says which one ran.
TEST(SampleMesh, CpuOpenVdbAndGpuSdfAllMeetTheTargets) {
  const TriangleMesh mesh = load_mesh(test::asset("sphere.obj"));
  const std::pair<gpu::Backend, CpuSdfMethod> paths[] = {{gpu::Backend::Cpu, CpuSdfMethod::Exact},
                                                         {gpu::Backend::Cpu, CpuSdfMethod::OpenVdb},
                                                         {gpu::Backend::Gpu, CpuSdfMethod::Exact},
                                                         {gpu::Backend::Auto, CpuSdfMethod::Exact}};
  for (const auto& [backend, method] : paths) {
    SampleSettings settings;
    settings.count = 300;
    settings.sdf_backend = backend;
    settings.cpu_sdf = method;
    const SampleResult result = sample_mesh(shared_context(), mesh, settings);
    const bool cpu = backend == gpu::Backend::Cpu || (backend == gpu::Backend::Auto && shared_context().software());
    EXPECT_EQ(result.sdf_on_cpu(), cpu);
    EXPECT_EQ(result.sdf_path == SdfPath::OpenVdb, method == CpuSdfMethod::OpenVdb);  // auto: exact at this size
    EXPECT_GT(result.field.band_voxels, 0u);
    EXPECT_GT(result.stages.sdf, 0.0);
    EXPECT_GT(result.stages.relaxation, 0.0);
    EXPECT_EQ(result.probes, probe_count(result.body.positions.size(), settings));
    expect_meets_quality_targets(mesh, result, settings.density);
  }
}

// On a software renderer the exact CPU field is the automatic choice at any size (its sweep over the
// triangles is faster than OpenVDB's meshToVolume and than llvmpipe's scan conversion), here on a
// grid above 2^23 voxels, where OpenVDB's field was taken before the sweep; the body meets the
// targets. Asking for OpenVDB with the winding-number sign is refused (OpenVDB's signs need a
// closed mesh).
TEST(SampleMesh, LargeGridsOnASoftwareRendererTakeTheExactField) {
  if (!shared_context().software()) GTEST_SKIP() << "auto takes the GPU scan on a hardware GPU";
  const TriangleMesh mesh = load_mesh(test::asset("sphere.obj"));  // radius 5 cm
  SampleSettings settings;
  settings.count = 300;
  settings.voxel_size = 0.1 / 220.0;  // 220+ voxels a side: above 2^23
  const SampleResult result = sample_mesh(shared_context(), mesh, settings);
  EXPECT_EQ(result.sdf_path, SdfPath::Exact);
  EXPECT_GT(result.field.band_voxels, 100'000u);
  expect_meets_quality_targets(mesh, result, settings.density);

  settings.sign = sdf::SignMethod::Winding;
  EXPECT_EQ(sample_mesh(shared_context(), mesh, settings).sdf_path, SdfPath::Exact);
  settings.sdf_backend = gpu::Backend::Cpu;
  settings.cpu_sdf = CpuSdfMethod::OpenVdb;
  try {
    sample_mesh(shared_context(), mesh, settings);
    FAIL() << "--sdf-backend openvdb with the winding-number sign ran";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--sdf-backend openvdb"), std::string::npos) << e.what();
  }
}

// Both relaxations give a body that meets the targets: the CPU one (the default on a software
// renderer, gpu::Backend::Auto) and the GPU kernels; the result says which one ran.
TEST(SampleMesh, CpuAndGpuRelaxationBothMeetTheTargets) {
  const TriangleMesh mesh = load_mesh(test::asset("torus.obj"));
  for (const gpu::Backend backend : {gpu::Backend::Cpu, gpu::Backend::Gpu, gpu::Backend::Auto}) {
    SampleSettings settings;
    settings.count = 300;
    settings.backend = backend;
    const SampleResult result = sample_mesh(shared_context(), mesh, settings);
    const bool cpu =
        backend == gpu::Backend::Cpu || (backend == gpu::Backend::Auto && shared_context().software());
    EXPECT_EQ(result.relax_on_cpu, cpu);
    EXPECT_EQ(result.certificate_on_cpu, cpu);
    EXPECT_EQ(result.field.gpu_bytes > 0, !cpu);  // the CPU path uploads no field
    EXPECT_GT(result.stages.relaxation, 0.0);
    expect_meets_quality_targets(mesh, result, settings.density);
  }
}

// Without a GL context (a null one) the CPU backend runs every stage on the CPU, auto takes it, and
// a stage that needs the GPU says so.
TEST(SampleMesh, CpuBackendNeedsNoGlContext) {
  const TriangleMesh mesh = load_mesh(test::asset("sphere.obj"));
  for (const gpu::Backend backend : {gpu::Backend::Cpu, gpu::Backend::Auto}) {
    SampleSettings settings;
    settings.count = 300;
    settings.backend = backend;
    const SampleResult result = sample_mesh(nullptr, mesh, settings);
    EXPECT_TRUE(result.sdf_on_cpu());
    EXPECT_TRUE(result.relax_on_cpu);
    EXPECT_TRUE(result.certificate_on_cpu);
    expect_meets_quality_targets(mesh, result, settings.density);
  }
  SampleSettings settings;
  settings.count = 300;
  settings.backend = gpu::Backend::Gpu;
  EXPECT_THROW(sample_mesh(nullptr, mesh, settings), Error);
}

TEST(SampleMesh, ZeroVolumeMeshIsRefused) {
  // A closed but flat mesh: two copies of one square with opposite windings.
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  flat.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 2, 1}, {0, 3, 2}};
  SampleSettings settings;
  settings.count = 100;
  EXPECT_THROW(sample_mesh(shared_context(), flat, settings), InputError);
}

}  // namespace
}  // namespace ts::sampler
