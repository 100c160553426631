#pragma once
// Nearest-point queries over a fixed point set with a hashed uniform grid: points are counting-sorted
// into hash buckets of their cell, a query visits cubic shells of cells around its own cell until the
// best distance found is no larger than the distance to any cell not yet visited. Hashing keeps memory
// proportional to the point count (a dense grid over a surface's bounding box grows like N^1.5), and
// a bucket shared by colliding cells only adds candidates, never hides one, so answers stay exact.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <span>
#include <unordered_map>
#include <vector>

namespace ts::sampler {

struct NearestPoint {
  std::size_t index = std::numeric_limits<std::size_t>::max();  // into the original point list
  double distance = std::numeric_limits<double>::infinity();      // m
};

class PointGrid {
 public:
  // cell_size [m] > 0: about the typical nearest distance keeps queries to one shell of 27 cells.
  PointGrid(std::span<const Eigen::Vector3d> points, double cell_size);

  // The point nearest to q other than `exclude` (an index into the original list). Exact. Thread-safe.
  NearestPoint nearest(const Eigen::Vector3d& q,
                       std::size_t exclude = std::numeric_limits<std::size_t>::max()) const;

  std::size_t size() const { return points_.size(); }
  double cell_size() const { return cell_size_; }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const;
  std::size_t bucket_of(const Eigen::Vector3i& cell) const;
  void scan_bucket(const Eigen::Vector3i& cell, const Eigen::Vector3d& q, std::size_t exclude,
                   NearestPoint& best) const;
  std::size_t scan_shell(const Eigen::Vector3i& center, int r, const Eigen::Vector3d& q, std::size_t exclude,
                         NearestPoint& best) const;
  void scan_all(const Eigen::Vector3d& q, std::size_t exclude, NearestPoint& best) const;

  double cell_size_;
  std::size_t mask_ = 0;                      // bucket count - 1 (a power of two)
  std::vector<std::uint32_t> bucket_start_;   // bucket b holds sorted entries [start[b], start[b+1])
  std::vector<Eigen::Vector3d> points_;       // m, in bucket order
  std::vector<std::uint32_t> original_;       // index in the input of each sorted point
  Eigen::Vector3i cell_min_, cell_max_;       // cells of the points' bounding box
};

// Greedy selection of well-separated points, deepest first (holes of a coverage measurement): a
// candidate is taken when no earlier pick lies within that pick's exclusion radius of it. Picks are
// binned in cells as large as the largest radius (the first pick's, the deepest), so a candidate
// checks only the picks in its 27 cells. Offer candidates in order of decreasing radius.
class SeparatedPicks {
 public:
  explicit SeparatedPicks(double largest_radius);  // [m]
  // Whether `p` (m) lies outside every earlier pick's exclusion radius.
  bool separated(const Eigen::Vector3d& p) const;
  // Takes `p` (m) with exclusion radius `radius` [m].
  void add(const Eigen::Vector3d& p, double radius);
  // Both: takes `p` unless it is too close to an earlier pick.
  bool try_add(const Eigen::Vector3d& p, double radius);
  std::size_t size() const { return picks_.size(); }

 private:
  using Cell = Eigen::Array<std::int64_t, 3, 1>;
  Cell cell_of(const Eigen::Vector3d& p) const;
  static std::uint64_t key(const Cell& c);

  double cell_;
  std::vector<std::pair<Eigen::Vector3d, double>> picks_;  // position [m], exclusion radius [m]
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> bins_;
};

}  // namespace ts::sampler
