#include "sampler/sampling_quality.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <algorithm>
#include <random>

#include "core/error.h"
#include "core/splitmix.h"
#include "sampler/point_grid.h"
#include "sampler/surface_points.h"

namespace ts::sampler {
namespace {

// Probes per generator: large enough that seeding (312 words) is negligible, small enough that two
// cores share a million probes evenly.
constexpr std::size_t kProbesPerChunk = 1 << 14;

// Probe k of a coverage measurement, reproducible alone: its chunk's generator, advanced past the
// three draws of each earlier probe of the chunk.
class ProbeSource {
 public:
  ProbeSource(const AreaTable& table, std::uint64_t seed) : table_(table), seed_(seed) {}

  std::mt19937_64 chunk_generator(std::size_t chunk) const {
    return std::mt19937_64(splitmix64(seed_ ^ splitmix64(chunk)));
  }
  UncoveredPoint next(std::mt19937_64& rng) const {
    UncoveredPoint p;
    p.triangle = table_.pick_triangle(uniform01(rng));
    const double u1 = uniform01(rng);
    const double u2 = uniform01(rng);
    p.position = table_.point_in_triangle(p.triangle, u1, u2);
    return p;
  }
  UncoveredPoint probe(std::size_t k) const {
    std::mt19937_64 rng = chunk_generator(k / kProbesPerChunk);
    rng.discard(3 * (k % kProbesPerChunk));
    UncoveredPoint p = next(rng);
    p.normal = table_.face_normal(p.triangle);
    return p;
  }

 private:
  const AreaTable& table_;
  std::uint64_t seed_;
};

// Deepest first; equal depths by probe index, so the order is the same on every run.
struct RankedProbe {
  float depth;
  std::uint32_t index;
  bool operator<(const RankedProbe& o) const { return depth > o.depth || (depth == o.depth && index < o.index); }
};

// Greedy selection of well-separated deep probes (sampler/point_grid.h: SeparatedPicks).
std::vector<UncoveredPoint> select_worst(const ProbeSource& source, const PointGrid& grid,
                                         std::vector<RankedProbe> ranked, const std::vector<Eigen::Vector3f>& positions,
                                         const CoverageSettings& settings) {
  std::vector<UncoveredPoint> picked;
  if (settings.worst_k == 0 || ranked.empty()) return picked;
  tbb::parallel_sort(ranked.begin(), ranked.end());
  SeparatedPicks picks(settings.separation * ranked.front().depth);
  for (const RankedProbe& candidate : ranked) {
    if (picked.size() == settings.worst_k || !(candidate.depth > settings.min_depth)) break;
    if (!picks.separated(positions[candidate.index].cast<double>())) continue;
    // The stored float position only screens; the pick is regenerated exactly, with its exact depth.
    UncoveredPoint p = source.probe(candidate.index);
    p.depth = grid.nearest(p.position).distance;
    picks.add(p.position, settings.separation * p.depth);
    picked.push_back(p);
  }
  return picked;
}

std::vector<Eigen::Vector3d> to_double(std::span<const Eigen::Vector3f> points) {
  std::vector<Eigen::Vector3d> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = points[i].cast<double>();
  return out;
}

}  // namespace

double hex_spacing(double area, std::size_t count) {
  return std::sqrt(2.0 * area / (std::sqrt(3.0) * static_cast<double>(count)));
}

double particles_for_covering_radius(double area, double covering_radius, double covering_over_spacing) {
  const double spacing = covering_radius / covering_over_spacing;
  return 2.0 * area / (std::sqrt(3.0) * spacing * spacing);
}

CoverageResult measure_coverage(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> samples,
                                const CoverageSettings& settings) {
  if (samples.empty()) throw Error(ExitCode::Internal, "measure_coverage: no samples");
  const AreaTable table(mesh);
  const PointGrid grid(samples, hex_spacing(table.total_area(), samples.size()));
  const ProbeSource source(table, settings.seed);
  const std::size_t n = std::max<std::size_t>(settings.probes, 1);
  const std::size_t chunks = (n + kProbesPerChunk - 1) / kProbesPerChunk;
  const bool keep = settings.worst_k > 0;
  std::vector<RankedProbe> ranked(keep ? n : 0);
  std::vector<Eigen::Vector3f> positions(keep ? n : 0);
  std::vector<RankedProbe> chunk_deepest(chunks);

  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t chunk = range.begin(); chunk != range.end(); ++chunk) {
      std::mt19937_64 rng = source.chunk_generator(chunk);
      RankedProbe deepest{-1.0f, 0};
      double deepest_depth = -1.0;
      const std::size_t end = std::min(n, (chunk + 1) * kProbesPerChunk);
      for (std::size_t k = chunk * kProbesPerChunk; k < end; ++k) {
        const Eigen::Vector3d p = source.next(rng).position;
        const double depth = grid.nearest(p).distance;
        if (depth > deepest_depth) {
          deepest_depth = depth;
          deepest = {static_cast<float>(depth), static_cast<std::uint32_t>(k)};
        }
        if (keep) {
          ranked[k] = {static_cast<float>(depth), static_cast<std::uint32_t>(k)};
          positions[k] = p.cast<float>();
        }
      }
      chunk_deepest[chunk] = deepest;
    }
  });

  // The deepest probe, regenerated to recover its exact depth (chunks kept only a float).
  std::size_t deepest_chunk = 0;
  CoverageResult result;
  result.probes = n;
  for (std::size_t c = 0; c < chunks; ++c) {
    if (chunk_deepest[c] < chunk_deepest[deepest_chunk]) deepest_chunk = c;
  }
  // Float rounding may tie or swap near-equal depths across chunks: compare the exact candidates.
  result.deepest.depth = -1.0;
  for (std::size_t c = 0; c < chunks; ++c) {
    if (chunk_deepest[c].depth < chunk_deepest[deepest_chunk].depth * (1.0f - 1e-6f)) continue;
    UncoveredPoint p = source.probe(chunk_deepest[c].index);
    p.depth = grid.nearest(p.position).distance;
    if (p.depth > result.deepest.depth) result.deepest = p;
  }
  result.covering_radius = result.deepest.depth;
  result.worst = select_worst(source, grid, std::move(ranked), positions, settings);
  return result;
}

CoverageResult measure_coverage(const TriangleMesh& mesh, std::span<const Eigen::Vector3f> samples,
                                const CoverageSettings& settings) {
  const std::vector<Eigen::Vector3d> points = to_double(samples);
  return measure_coverage(mesh, points, settings);
}

std::vector<double> nearest_neighbour_distances(std::span<const Eigen::Vector3d> samples) {
  std::vector<double> nn(samples.size(), std::numeric_limits<double>::infinity());
  if (samples.size() < 2) return nn;
  Eigen::Vector3d lo = samples[0], hi = samples[0];
  for (const auto& p : samples) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // A cell about the spacing of the points spread over half their bounding box's surface (a plane
  // patch: its area; a sphere: 12 R^2 against 4 pi R^2). The grid is exact for any cell size; this only
  // keeps the searched shells few and short.
  const Eigen::Vector3d e = hi - lo;
  const double spread_area = e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  // Collinear points have no spread area: their spacing along the line takes over.
  const double n = static_cast<double>(samples.size());
  const double cell = std::max({hex_spacing(spread_area, samples.size()), e.maxCoeff() / n, 1e-300});
  const PointGrid grid(samples, cell);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        nn[i] = grid.nearest(samples[i], i).distance;
                      }
                    });
  return nn;
}

SpacingStatistics spacing_statistics(double area, std::span<const Eigen::Vector3d> samples) {
  SpacingStatistics s;
  s.d_hex = samples.empty() ? 0.0 : hex_spacing(area, samples.size());
  if (samples.size() < 2) return s;
  const std::vector<double> nn = nearest_neighbour_distances(samples);
  double sum = 0.0, min = nn[0];
  for (const double d : nn) {
    sum += d;
    min = std::min(min, d);
  }
  s.mean_nn = sum / static_cast<double>(nn.size());
  double var = 0.0;
  for (const double d : nn) var += (d - s.mean_nn) * (d - s.mean_nn);
  var /= static_cast<double>(nn.size());
  s.cv_nn = s.mean_nn > 0.0 ? std::sqrt(var) / s.mean_nn : 0.0;
  s.relative_radius = min / s.d_hex;
  return s;
}

double max_distance_to_surface(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> samples) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Triangles = std::vector<Kernel::Triangle_3>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CGAL::AABB_triangle_primitive<Kernel, Triangles::const_iterator>>>;
  auto point = [](const Eigen::Vector3d& v) { return Kernel::Point_3(v.x(), v.y(), v.z()); };
  Triangles triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    Kernel::Triangle_3 tri(point(mesh.vertices[t[0]]), point(mesh.vertices[t[1]]), point(mesh.vertices[t[2]]));
    if (!tri.is_degenerate()) triangles.push_back(tri);  // their edges belong to their neighbours
  }
  if (triangles.empty() || samples.empty()) return 0.0;
  Tree tree(triangles.begin(), triangles.end());
  // Built before the parallel queries: CGAL builds both lazily on the first query, which would race.
  tree.build();
  tree.accelerate_distance_queries();
  const double max_sq = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, samples.size(), 256), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double running) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          running = std::max(running, CGAL::to_double(tree.squared_distance(point(samples[i]))));
        }
        return running;
      },
      [](double a, double b) { return std::max(a, b); });
  return std::sqrt(max_sq);
}

SamplingQuality measure_quality(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> samples,
                                double particle_radius, const CoverageSettings& settings) {
  SamplingQuality q;
  q.count = samples.size();
  q.area = surface_area(mesh);
  const SpacingStatistics spacing = spacing_statistics(q.area, samples);
  q.d_hex = spacing.d_hex;
  q.relative_radius = spacing.relative_radius;
  q.mean_nn = spacing.mean_nn;
  q.cv_nn = spacing.cv_nn;
  const CoverageResult coverage = measure_coverage(mesh, samples, settings);
  q.covering_radius = coverage.covering_radius;
  q.covering_over_r = coverage.covering_radius / particle_radius;
  q.worst_uncovered_point = coverage.deepest.position;
  q.max_abs_phi = max_distance_to_surface(mesh, samples);
  return q;
}

}  // namespace ts::sampler
