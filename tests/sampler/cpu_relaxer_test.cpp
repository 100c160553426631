// The CPU relaxation (sampler/cpu_relaxer.h) against the GPU one: the same algorithm on the same
// sparse field from the same seeds must give arrangements of the same quality. The two are not equal
// particle for particle: the CPU sums in double, the GPU in float, and a many-particle relaxation
// amplifies any rounding difference into a different (equally good) arrangement, as a different seed
// would. So the figures are compared, with tolerances the size of their seed-to-seed spread: rho
// (min NN / d_hex, an extreme value) within 0.06, CV of NN distances within 0.01, covering radius
// over probes within 0.06 d_hex; both meet the targets (rho >= 0.7, CV <= 0.1) and both
// converge. After the projection steps both sit on the zero level set of the same trilinear field:
// their largest distance from the mesh agrees within 0.01 d_hex and is below 0.1 d_hex. (Found after
// the first run, 2026-12-03: a bound of 0.02 d_hex on each, set before it, failed on the torus (CPU
// 0.019, GPU 0.022) and the trefoil (0.077, 0.076): it measured the field's trilinear error on a thin
// curved tube, not either relaxer; sample_mesh's exact projection removes that error afterwards.)
#include "sampler/cpu_relaxer.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <ostream>
#include <random>
#include <string>

#include "core/mesh_io.h"
#include "gpu/context.h"
#include "gpu/host_sync.h"
#include "sampler/gpu_relaxer.h"
#include "sampler/sampling_quality.h"
#include "sampler/surface_points.h"
#include "sdf/exact_sdf.h"
#include "sdf/host_field.h"
#include "sdf/sparse_field.h"
#include "tests/test_meshes.h"
#include "tests/test_support.h"

namespace ts::sampler {
namespace {

gpu::Context& shared_context() {
  static gpu::Context context;
  return context;
}

constexpr double kBandVoxels = 4.0;  // as sample_mesh

// A mesh, its exact level set at voxel 0.36 d_hex (sample_mesh's r / 2 at coverage 1), the same
// NanoVDB grid for both relaxers, and `count` area-uniform seeds relative to the grid's voxel (0,0,0).
struct Scene {
  TriangleMesh mesh;
  double area = 0.0, d_hex = 0.0;
  sdf::GridSpec spec;
  openvdb::FloatGrid::Ptr level_set;
  std::vector<Eigen::Vector3f> seeds;
  RelaxSettings settings;

  sdf::HostField host_field() const { return sdf::HostField(sdf::to_nanovdb(*level_set), spec, kBandVoxels); }
  sdf::SparseField gpu_field() const {
    return sdf::SparseField(sdf::to_nanovdb(*level_set), spec, kBandVoxels);
  }
};

Scene make_scene(TriangleMesh mesh, std::size_t count, std::uint64_t seed) {
  Scene s;
  s.mesh = std::move(mesh);
  s.area = surface_area(s.mesh);
  s.d_hex = hex_spacing(s.area, count);
  s.spec = test::grid_around(s.mesh, 0.36 * s.d_hex, 6);
  const sdf::ExactDistance exact(s.mesh);
  s.level_set = sdf::exact_sdf_grid(exact, s.mesh, s.spec, kBandVoxels, sdf::SignMethod::Pseudonormal, true);
  std::mt19937_64 rng(seed);
  for (const auto& p : sample_surface_points(s.mesh, count, rng).positions)
    s.seeds.push_back((p - s.spec.origin).cast<float>());
  s.settings.spacing = s.d_hex;
  s.settings.band_limit = 0.95 * kBandVoxels * s.spec.voxel_size;
  return s;
}

struct Figures {
  double rho = 0.0, cv = 0.0, covering_over_d_hex = 0.0, max_phi_over_d_hex = 0.0;
};

Figures measure(const Scene& s, const std::vector<Eigen::Vector3f>& local) {
  std::vector<Eigen::Vector3d> world;
  for (const auto& p : local) world.push_back(p.cast<double>() + s.spec.origin);
  const SpacingStatistics spacing = spacing_statistics(s.area, world);
  CoverageSettings probes;
  probes.probes = 200'000;
  probes.seed = 99;
  Figures f;
  f.rho = spacing.relative_radius;
  f.cv = spacing.cv_nn;
  f.covering_over_d_hex =
      measure_coverage(s.mesh, std::span<const Eigen::Vector3d>(world), probes).covering_radius / s.d_hex;
  f.max_phi_over_d_hex = max_distance_to_surface(s.mesh, world) / s.d_hex;
  return f;
}

struct Case {
  std::string name;
  std::size_t count;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name << " " << c.count; }

TriangleMesh load_case(const std::string& name) {
  if (name == "icosphere") return test::icosphere(1.0, 4);
  if (name == "torus") return make_torus(1.0, 0.45, 64, 32);
  return load_mesh(test::asset(name + ".obj"));
}

class CpuAgainstGpu : public ::testing::TestWithParam<Case> {};

TEST_P(CpuAgainstGpu, SameSeedsReachTheSameQualityFigures) {
  gpu::Context& context = shared_context();  // before the GPU field is uploaded
  const Scene s = make_scene(load_case(GetParam().name), GetParam().count, 11);
  std::vector<Eigen::Vector3f> cpu = s.seeds, gpu = s.seeds;
  CpuRelaxer cpu_relaxer(s.host_field());
  GpuRelaxer gpu_relaxer(context, s.gpu_field());
  const RelaxStats cpu_stats = cpu_relaxer.relax(cpu, s.settings);
  const RelaxStats gpu_stats = gpu_relaxer.relax(gpu, s.settings);
  const Figures c = measure(s, cpu), g = measure(s, gpu);
  std::printf(
      "  %s, %zu seeds: CPU %d iterations, rho %.3f, CV %.4f, c %.3f d_hex, |phi| %.2e d_hex; GPU %d "
      "iterations, rho %.3f, CV %.4f, c %.3f d_hex, |phi| %.2e d_hex\n",
      GetParam().name.c_str(), s.seeds.size(), cpu_stats.iterations, c.rho, c.cv, c.covering_over_d_hex,
      c.max_phi_over_d_hex, gpu_stats.iterations, g.rho, g.cv, g.covering_over_d_hex, g.max_phi_over_d_hex);
  EXPECT_EQ(cpu.size(), s.seeds.size());
  EXPECT_EQ(cpu_stats.removed, gpu_stats.removed);
  EXPECT_TRUE(cpu_stats.converged);
  EXPECT_TRUE(gpu_stats.converged);
  EXPECT_NEAR(c.rho, g.rho, 0.06);
  EXPECT_NEAR(c.cv, g.cv, 0.01);
  EXPECT_NEAR(c.covering_over_d_hex, g.covering_over_d_hex, 0.06);
  EXPECT_NEAR(c.max_phi_over_d_hex, g.max_phi_over_d_hex, 0.01);
  for (const Figures& f : {c, g}) {
    EXPECT_GE(f.rho, 0.7);
    EXPECT_LE(f.cv, 0.1);
    EXPECT_LE(f.max_phi_over_d_hex, 0.1);
  }
}

INSTANTIATE_TEST_SUITE_P(Meshes, CpuAgainstGpu,
                         ::testing::Values(Case{"icosphere", 600}, Case{"torus", 800}, Case{"trefoil", 800}),
                         [](const auto& test) {
                           return test.param.name + "_" + std::to_string(test.param.count);
                         });

// Frozen particles (mobile 0) keep their exact float positions, mobile ones move.
TEST(CpuRelaxer, MovesOnlyTheMobileParticlesAndFrozenOnesStayBitForBit) {
  const Scene s = make_scene(test::icosphere(1.0, 3), 300, 5);
  std::vector<Eigen::Vector3f> positions = s.seeds;
  std::vector<std::uint8_t> mobile(positions.size());
  for (std::size_t i = 0; i < mobile.size(); ++i) mobile[i] = i % 3 == 0 ? 1 : 0;
  const std::vector<std::uint8_t> flags = mobile;
  CpuRelaxer relaxer(s.host_field());
  RelaxSettings settings = s.settings;
  settings.max_iterations = 100;
  const RelaxStats stats = relaxer.relax(positions, settings, {}, &mobile);
  ASSERT_EQ(stats.removed, 0u);
  ASSERT_EQ(positions.size(), s.seeds.size());
  EXPECT_EQ(mobile, flags);
  std::size_t moved = 0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!flags[i]) {
      ASSERT_EQ(positions[i], s.seeds[i]) << i;
    } else {
      moved += (positions[i] - s.seeds[i]).norm() > 1e-3 * s.d_hex;
    }
  }
  EXPECT_GT(moved, flags.size() / 3 * 9 / 10);  // nearly every mobile seed is pushed by its neighbours
}

// Particles outside the band are dropped at the next check, their mobile flags with them, the rest
// keep their order; the GPU relaxer drops the same ones.
TEST(CpuRelaxer, DropsParticlesThatLeftTheBandWithTheirFlagsAsTheGpuDoes) {
  gpu::Context& context = shared_context();  // before the GPU field is uploaded
  const Scene s = make_scene(test::icosphere(1.0, 3), 200, 6);
  std::vector<Eigen::Vector3f> seeds = s.seeds;
  std::vector<std::uint8_t> flags(seeds.size(), 1);
  std::vector<std::uint32_t> tags(seeds.size());
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    tags[i] = static_cast<std::uint32_t>(i);
    if (i % 4 == 1) flags[i] = 0;
    if (i % 10 == 3) {  // far out along the normal: |phi| = 2 band limits
      const Eigen::Vector3d world = seeds[i].cast<double>() + s.spec.origin;
      seeds[i] = (world.normalized() * (1.0 + 2.0 * s.settings.band_limit) - s.spec.origin).cast<float>();
    }
  }
  RelaxSettings settings = s.settings;
  settings.max_iterations = 20;
  settings.check_every = 5;
  auto run = [&](ParticleRelaxer& relaxer) {
    std::vector<Eigen::Vector3f> positions = seeds;
    std::vector<std::uint8_t> mobile = flags;
    const RelaxStats stats = relaxer.relax(positions, settings, {}, &mobile);
    EXPECT_EQ(stats.removed, 20u);
    EXPECT_EQ(positions.size(), seeds.size() - 20);
    return std::pair(positions, mobile);
  };
  CpuRelaxer cpu_relaxer(s.host_field());
  GpuRelaxer gpu_relaxer(context, s.gpu_field());
  const auto [cpu, cpu_mobile] = run(cpu_relaxer);
  const auto [gpu, gpu_mobile] = run(gpu_relaxer);
  std::vector<std::uint8_t> expected;
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < seeds.size(); ++i)
    if (i % 10 != 3) expected.push_back(flags[i]), kept.push_back(i);
  EXPECT_EQ(cpu_mobile, expected);
  EXPECT_EQ(gpu_mobile, expected);
  // The frozen survivors, in their order, are where they were: the order is kept.
  for (std::size_t m = 0; m < kept.size(); ++m) {
    if (!expected[m]) {
      EXPECT_EQ(cpu[m], seeds[kept[m]]) << m;
      EXPECT_EQ(gpu[m], seeds[kept[m]]) << m;
    }
  }
}

// No GPU is involved: the same phases as the GPU relaxer's, iterations and checks counted, no round trip.
TEST(CpuRelaxer, CountsIterationsAndChecksWithoutAnyHostGpuRoundTrip) {
  const Scene s = make_scene(test::icosphere(1.0, 2), 100, 7);
  CpuRelaxer relaxer(s.host_field());
  RelaxSettings settings = s.settings;
  settings.max_iterations = 25;
  settings.check_every = 10;
  settings.tolerance = 0.0;  // never converged: all 25 iterations run
  std::vector<Eigen::Vector3f> positions = s.seeds;
  int progress_calls = 0;
  const gpu::HostSyncCounts before = gpu::host_sync_counts();
  const RelaxStats stats =
      relaxer.relax(positions, settings, [&](int, std::size_t, double) { ++progress_calls; });
  EXPECT_EQ((gpu::host_sync_counts() - before).total(), 0);
  EXPECT_EQ(stats.iterations, 25);
  EXPECT_EQ(stats.checks, 3);
  EXPECT_EQ(progress_calls, 3);
  EXPECT_FALSE(stats.converged);
  const std::vector<gpu::HostSyncPhase> phases = relaxer.round_trips();
  ASSERT_EQ(phases.size(), 3u);
  EXPECT_EQ(phases[0].units, 25);
  EXPECT_EQ(phases[1].units, 3);
  for (const auto& phase : phases) EXPECT_EQ(phase.counts.total(), 0);
  EXPECT_NE(relaxer.timing_report().find("25 iterations, 3 checks"), std::string::npos)
      << relaxer.timing_report();
}

// Jacobi steps and sums in a fixed order: the same seeds give the same result bit for bit, on one
// thread or on all.
TEST(CpuRelaxer, GivesTheSameResultBitForBitOnOneThreadOrMany) {
  const Scene s = make_scene(test::icosphere(1.0, 3), 400, 8);
  RelaxSettings settings = s.settings;
  settings.max_iterations = 60;
  CpuRelaxer relaxer(s.host_field());
  std::vector<Eigen::Vector3f> many = s.seeds, again = s.seeds, one = s.seeds;
  relaxer.relax(many, settings);
  relaxer.relax(again, settings);
  {
    const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    relaxer.relax(one, settings);
  }
  ASSERT_EQ(many.size(), one.size());
  for (std::size_t i = 0; i < many.size(); ++i) {
    ASSERT_EQ(many[i], again[i]) << i;
    ASSERT_EQ(many[i], one[i]) << i;
  }
}

}  // namespace
}  // namespace ts::sampler
