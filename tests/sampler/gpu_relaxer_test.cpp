// The GPU relaxation alone, on a sphere seeded at random: it must spread particles evenly
// (relative radius, CV of nearest-neighbour distances) and keep them on the surface.
#include "sampler/gpu_relaxer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "sdf/leaf_field.h"
#include "sdf/pseudonormals.h"
#include "sdf/sparse_field.h"
#include "tests/test_meshes.h"

namespace ts::sampler {
namespace {

sdf::GridSpec grid_around_sphere(double radius, double h, int padding) {
  sdf::GridSpec s;
  s.voxel_size = h;
  const int half = static_cast<int>(std::ceil(radius / h)) + padding;
  s.index_offset = Eigen::Vector3i::Constant(-half);
  s.dims = Eigen::Vector3i::Constant(2 * half + 1);
  s.origin = h * s.index_offset.cast<double>();
  return s;
}

struct NearestNeighbours {
  double min = 1e300, mean = 0.0, cv = 0.0;
};

NearestNeighbours nearest_neighbours(const std::vector<Eigen::Vector3f>& p) {
  std::vector<double> nn(p.size(), 1e300);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = 0; j < p.size(); ++j)
      if (i != j) nn[i] = std::min(nn[i], static_cast<double>((p[i] - p[j]).norm()));
  NearestNeighbours r;
  for (double d : nn) r.min = std::min(r.min, d), r.mean += d;
  r.mean /= static_cast<double>(nn.size());
  double var = 0.0;
  for (double d : nn) var += (d - r.mean) * (d - r.mean);
  r.cv = std::sqrt(var / static_cast<double>(nn.size())) / r.mean;
  return r;
}

// Relaxes the same 200 seeds near the unit sphere with both relaxers: for two fields that read alike
// the particles must come out bit for bit the same, and moved (the field and the repulsion acted).
void expect_bitwise_same_relaxation(GpuRelaxer& first, GpuRelaxer& second, const sdf::GridSpec& spec,
                                    unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  std::vector<Eigen::Vector3f> seeds(200);
  for (auto& p : seeds) p = (Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized() - spec.origin).cast<float>();
  RelaxSettings settings;
  settings.spacing = 0.2;
  settings.band_limit = 0.25;
  settings.max_iterations = 30;
  auto a = seeds, b = seeds;
  const RelaxStats sa = first.relax(a, settings);
  const RelaxStats sb = second.relax(b, settings);
  EXPECT_EQ(sa.iterations, sb.iterations);
  ASSERT_EQ(a.size(), b.size());
  double moved = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i], b[i]) << i;
    moved = std::max(moved, static_cast<double>((a[i] - seeds[i]).norm()));
  }
  EXPECT_GT(moved, 0.01);
}

class Relaxer : public ::testing::Test {
 protected:
  gpu::Context context;
};

TEST_F(Relaxer, SpreadsRandomSeedsEvenlyOverASphere) {
  const double radius = 1.0;
  const std::size_t n = 600;
  const double area = 4.0 * M_PI * radius * radius;
  const double d_hex = std::sqrt(2.0 * area / (std::sqrt(3.0) * static_cast<double>(n)));
  const TriangleMesh sphere = test::icosphere(radius, 4);
  const sdf::GridSpec spec = grid_around_sphere(radius, d_hex / 2.0, 6);
  sdf::ScanConvertOptions options;
  options.index_space_grid = true;
  options.band = 5.0;
  auto field = sdf::scan_convert(context, sphere, sdf::compute_pseudonormals(sphere), spec, options);

  std::mt19937_64 rng(42);
  std::normal_distribution<double> gauss;
  std::vector<Eigen::Vector3f> positions(n);
  for (auto& p : positions) {
    const Eigen::Vector3d dir = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    p = (radius * dir - spec.origin).cast<float>();
  }
  const NearestNeighbours before = nearest_neighbours(positions);

  GpuRelaxer relaxer(context, sdf::SparseField(*field.grid, spec, options.band));
  RelaxSettings settings;
  settings.spacing = d_hex;
  settings.band_limit = 4.5 * spec.voxel_size;
  settings.max_iterations = 600;
  const RelaxStats stats = relaxer.relax(positions, settings);
  ASSERT_EQ(positions.size(), n);
  EXPECT_EQ(stats.removed, 0u);
  const NearestNeighbours after = nearest_neighbours(positions);
  EXPECT_LT(before.min / d_hex, 0.2);
  EXPECT_GE(after.min / d_hex, 0.7) << "iterations " << stats.iterations;
  EXPECT_LE(after.cv, 0.1);
  double worst_off_surface = 0.0;
  for (const auto& p : positions)
    worst_off_surface = std::max(worst_off_surface, std::abs((p.cast<double>() + spec.origin).norm() - radius));
  // The icosphere's facets sit up to ~1e-3 inside the unit sphere; the particles follow the facets.
  EXPECT_LT(worst_off_surface, 0.05 * d_hex);
}

// A coarse unit sphere's field, `count` seeds on it and settings that keep them all in the band: for
// tests of the loop rather than of the result's quality.
struct CoarseSphere {
  GpuRelaxer relaxer;
  std::vector<Eigen::Vector3f> seeds;
  RelaxSettings settings;
};

CoarseSphere coarse_sphere(gpu::Context& context, std::size_t count) {
  const TriangleMesh sphere = test::icosphere(1.0, 2);
  const sdf::GridSpec spec = grid_around_sphere(1.0, 0.1, 6);
  sdf::ScanConvertOptions options;
  options.index_space_grid = true;
  auto field = sdf::scan_convert(context, sphere, sdf::compute_pseudonormals(sphere), spec, options);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  std::vector<Eigen::Vector3f> seeds(count);
  for (auto& p : seeds) p = (Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized() - spec.origin).cast<float>();
  RelaxSettings settings;
  settings.spacing = 0.2;
  settings.band_limit = 0.25;
  return {GpuRelaxer(context, sdf::SparseField(*field.grid, spec, options.band)), std::move(seeds), settings};
}

TEST_F(Relaxer, SameSeedsGiveBitwiseTheSameResult) {
  auto [relaxer, seeds, settings] = coarse_sphere(context, 300);
  settings.max_iterations = 50;
  auto a = seeds, b = seeds;
  relaxer.relax(a, settings);
  relaxer.relax(b, settings);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << i;
}

// A field larger than one storage block (llvmpipe's 128 MiB holds no field of a 1M-particle bunny at
// r / 2) is uploaded in chunks, and the relaxation's kernels are compiled to read through them: the
// particles must move exactly as with one block.
TEST_F(Relaxer, AFieldCutIntoChunksRelaxesBitwiseAsOneBlock) {
  const TriangleMesh sphere = test::icosphere(1.0, 2);
  const sdf::GridSpec spec = grid_around_sphere(1.0, 0.1, 6);
  sdf::ScanConvertOptions options;
  options.index_space_grid = true;
  auto field = sdf::scan_convert(context, sphere, sdf::compute_pseudonormals(sphere), spec, options);
  sdf::SparseField whole_field(*field.grid, spec, options.band);
  const std::size_t bytes = whole_field.gpu_bytes();
  sdf::SparseField chunked_field(sdf::to_nanovdb(*field.grid), spec, options.band, bytes / 3);
  ASSERT_EQ(whole_field.chunk_count(), 1);
  ASSERT_GE(chunked_field.chunk_count(), 3);
  GpuRelaxer whole(context, std::move(whole_field));
  GpuRelaxer chunked(context, std::move(chunked_field));

  expect_bitwise_same_relaxation(whole, chunked, spec, 5);
}

// The field the scan conversion builds and keeps on the GPU (sdf::LeafField) reads voxel for voxel as
// the host's NanoVDB field from the same scan, so relaxing on it must move the particles exactly as on
// the uploaded field: the sampler's kernels run unchanged on either.
TEST_F(Relaxer, AFieldKeptOnTheGpuRelaxesBitwiseAsTheUploadedHostField) {
  const TriangleMesh sphere = test::icosphere(1.0, 2);
  const sdf::GridSpec spec = grid_around_sphere(1.0, 0.1, 6);
  sdf::ScanConvertOptions options;
  options.index_space_grid = true;
  options.gpu_field = true;
  auto field = sdf::scan_convert(context, sphere, sdf::compute_pseudonormals(sphere), spec, options);
  ASSERT_TRUE(field.field.has_value());
  GpuRelaxer uploaded(context, sdf::SparseField(*field.grid, spec, options.band));
  GpuRelaxer resident(context, std::make_unique<const sdf::LeafField>(std::move(*field.field)));

  expect_bitwise_same_relaxation(uploaded, resident, spec, 7);
}

// Iterations between convergence checks read nothing back; each check reads its reduction once, so
// M iterations checked every K make ceil(M / K) round trips, and the result's read-back one more.
TEST_F(Relaxer, MakesOneHostRoundTripPerConvergenceCheckAndNoneBetween) {
  auto [relaxer, seeds, settings] = coarse_sphere(context, 100);
  settings.max_iterations = 25;
  settings.check_every = 10;
  settings.tolerance = 0.0;  // never converged: all 25 iterations run
  const gpu::HostSyncCounts before = gpu::host_sync_counts();
  const RelaxStats stats = relaxer.relax(seeds, settings);
  const gpu::HostSyncCounts made = gpu::host_sync_counts() - before;
  ASSERT_EQ(stats.removed, 0u);
  EXPECT_EQ(stats.iterations, 25);
  EXPECT_EQ(stats.checks, 3);
  const std::vector<gpu::HostSyncPhase> phases = relaxer.round_trips();
  ASSERT_EQ(phases.size(), 3u);
  EXPECT_EQ(phases[0].units, 25);
  EXPECT_EQ(phases[0].counts.total(), 0);
  EXPECT_EQ(phases[1].units, 3);
  EXPECT_EQ(phases[1].counts.reads, 3);
  EXPECT_EQ(phases[1].counts.total(), 3);
  EXPECT_EQ(made.total(), 3 + 1);
  EXPECT_EQ(phases[2].counts, made);  // all of relax()
}

}  // namespace
}  // namespace ts::sampler
