#include "sampler/point_grid.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

namespace ts::sampler {
namespace {

// Cell coordinates are kept well inside int so that shell arithmetic never overflows.
constexpr double kMaxCell = 1 << 29;

}  // namespace

PointGrid::PointGrid(std::span<const Eigen::Vector3d> points, double cell_size) : cell_size_(cell_size) {
  assert(cell_size > 0.0);
  assert(points.size() < std::numeric_limits<std::uint32_t>::max());
  // Two buckets per point keeps collisions rare and buckets short.
  const std::size_t buckets = std::bit_ceil(std::max<std::size_t>(2 * points.size(), 64));
  mask_ = buckets - 1;
  cell_min_ = Eigen::Vector3i::Constant(std::numeric_limits<int>::max());
  cell_max_ = Eigen::Vector3i::Constant(std::numeric_limits<int>::min());

  std::vector<std::uint32_t> bucket(points.size());
  bucket_start_.assign(buckets + 1, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3i c = cell_of(points[i]);
    cell_min_ = cell_min_.cwiseMin(c);
    cell_max_ = cell_max_.cwiseMax(c);
    bucket[i] = static_cast<std::uint32_t>(bucket_of(c));
    ++bucket_start_[bucket[i] + 1];
  }
  for (std::size_t b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];

  // Counting sort, stable in input order so that ties resolve the same way on every run.
  std::vector<std::uint32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
  points_.resize(points.size());
  original_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint32_t slot = fill[bucket[i]]++;
    points_[slot] = points[i];
    original_[slot] = static_cast<std::uint32_t>(i);
  }
}

Eigen::Vector3i PointGrid::cell_of(const Eigen::Vector3d& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    c[a] = static_cast<int>(std::clamp(std::floor(p[a] / cell_size_), -kMaxCell, kMaxCell));
  }
  return c;
}

std::size_t PointGrid::bucket_of(const Eigen::Vector3i& cell) const {
  // Teschner et al. 2003, "Optimized spatial hashing for collision detection of deformable objects".
  const auto x = static_cast<std::uint64_t>(static_cast<std::int64_t>(cell.x())) * 73856093u;
  const auto y = static_cast<std::uint64_t>(static_cast<std::int64_t>(cell.y())) * 19349663u;
  const auto z = static_cast<std::uint64_t>(static_cast<std::int64_t>(cell.z())) * 83492791u;
  return static_cast<std::size_t>((x ^ y ^ z) & mask_);
}

void PointGrid::scan_bucket(const Eigen::Vector3i& cell, const Eigen::Vector3d& q, std::size_t exclude,
                            NearestPoint& best) const {
  const std::size_t b = bucket_of(cell);
  double best_sq = best.distance * best.distance;
  for (std::uint32_t k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
    const double d_sq = (points_[k] - q).squaredNorm();
    if (d_sq < best_sq && original_[k] != exclude) {
      best_sq = d_sq;
      best.index = original_[k];
      best.distance = std::sqrt(d_sq);
    } else if (d_sq == best_sq && original_[k] < best.index && original_[k] != exclude) {
      best.index = original_[k];  // equal distances: the lowest index, whatever the bucket order
    }
  }
}

// The cells at Chebyshev distance exactly r from `center`; returns how many were visited.
std::size_t PointGrid::scan_shell(const Eigen::Vector3i& center, int r, const Eigen::Vector3d& q, std::size_t exclude,
                                  NearestPoint& best) const {
  std::size_t visited = 0;
  for (int dx = -r; dx <= r; ++dx) {
    for (int dy = -r; dy <= r; ++dy) {
      const bool on_side = std::abs(dx) == r || std::abs(dy) == r;
      const int dz_step = on_side || r == 0 ? 1 : 2 * r;
      for (int dz = -r; dz <= r; dz += dz_step) {
        scan_bucket(center + Eigen::Vector3i(dx, dy, dz), q, exclude, best);
        ++visited;
      }
    }
  }
  return visited;
}

void PointGrid::scan_all(const Eigen::Vector3d& q, std::size_t exclude, NearestPoint& best) const {
  best = NearestPoint{};
  for (std::size_t b = 0; b + 1 < bucket_start_.size(); ++b) {
    if (bucket_start_[b] == bucket_start_[b + 1]) continue;
    for (std::uint32_t k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
      const double d_sq = (points_[k] - q).squaredNorm();
      const double best_sq = best.distance * best.distance;
      if (original_[k] == exclude) continue;
      if (d_sq < best_sq || (d_sq == best_sq && original_[k] < best.index)) {
        best.index = original_[k];
        best.distance = std::sqrt(d_sq);
      }
    }
  }
}

NearestPoint PointGrid::nearest(const Eigen::Vector3d& q, std::size_t exclude) const {
  NearestPoint best;
  if (points_.empty()) return best;
  const Eigen::Vector3i center = cell_of(q);
  // Once the cube of visited cells spans the points' bounding box of cells, every point was seen.
  const int last_ring = std::max({0, (center - cell_min_).maxCoeff(), (cell_max_ - center).maxCoeff()});
  // A query far from every point (or a cell much smaller than the spacing) would walk through
  // shells of empty cells; once that costs more than looking at every point, do that instead.
  const std::size_t cell_budget = 4 * points_.size() + 64;
  std::size_t visited = 0;
  for (int r = 0;; ++r) {
    visited += scan_shell(center, r, q, exclude, best);
    if (r >= last_ring) break;
    // Distance from q to the outside of the visited cube: no unvisited point is nearer.
    const Eigen::Vector3d lo = (center.array() - r).cast<double>().matrix() * cell_size_;
    const Eigen::Vector3d hi = (center.array() + r + 1).cast<double>().matrix() * cell_size_;
    const double clearance = std::min((q - lo).minCoeff(), (hi - q).minCoeff());
    if (best.distance <= clearance) break;
    if (visited > cell_budget) {
      scan_all(q, exclude, best);
      break;
    }
  }
  return best;
}

SeparatedPicks::SeparatedPicks(double largest_radius) : cell_(std::max(largest_radius, 1e-300)) {}

SeparatedPicks::Cell SeparatedPicks::cell_of(const Eigen::Vector3d& p) const {
  return (p / cell_).array().floor().cast<std::int64_t>();
}

std::uint64_t SeparatedPicks::key(const Cell& c) {
  return static_cast<std::uint64_t>(c.x()) * 73856093u ^ static_cast<std::uint64_t>(c.y()) * 19349663u ^
         static_cast<std::uint64_t>(c.z()) * 83492791u;
}

bool SeparatedPicks::separated(const Eigen::Vector3d& p) const {
  const Cell c = cell_of(p);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = bins_.find(key(c + Cell(dx, dy, dz)));
        if (it == bins_.end()) continue;
        for (const std::size_t j : it->second) {
          const auto& [q, radius] = picks_[j];
          if ((q - p).squaredNorm() < radius * radius) return false;
        }
      }
  return true;
}

void SeparatedPicks::add(const Eigen::Vector3d& p, double radius) {
  bins_[key(cell_of(p))].push_back(picks_.size());
  picks_.emplace_back(p, radius);
}

bool SeparatedPicks::try_add(const Eigen::Vector3d& p, double radius) {
  if (!separated(p)) return false;
  add(p, radius);
  return true;
}

}  // namespace ts::sampler
