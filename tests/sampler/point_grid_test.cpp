#include "sampler/point_grid.h"

#include <gtest/gtest.h>

#include <random>

#include "sampler/sampling_quality.h"

namespace ts::sampler {
namespace {

NearestPoint brute_force(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& q, std::size_t exclude) {
  NearestPoint best;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i] - q).norm();
    if (i != exclude && d < best.distance) best = {i, d};
  }
  return best;
}

std::vector<Eigen::Vector3d> clustered_points(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 400; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  for (int i = 0; i < 200; ++i) points.emplace_back(5.0 + 0.01 * u(rng), 0.01 * u(rng), 0.01 * u(rng));
  return points;
}

TEST(PointGrid, NearestMatchesBruteForceForAnyCellSize) {
  std::mt19937_64 rng(11);
  const std::vector<Eigen::Vector3d> points = clustered_points(rng);
  std::uniform_real_distribution<double> u(-3.0, 8.0);
  for (const double cell : {0.003, 0.1, 0.5, 20.0}) {
    const PointGrid grid(points, cell);
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3d q(u(rng), u(rng) * 0.5, u(rng) * 0.5);
      const NearestPoint expected = brute_force(points, q, points.size());
      const NearestPoint got = grid.nearest(q);
      EXPECT_EQ(got.index, expected.index) << "cell " << cell;
      EXPECT_DOUBLE_EQ(got.distance, expected.distance);
    }
  }
}

TEST(PointGrid, ExcludedPointIsSkipped) {
  std::mt19937_64 rng(12);
  const std::vector<Eigen::Vector3d> points = clustered_points(rng);
  const PointGrid grid(points, 0.2);
  for (std::size_t i = 0; i < points.size(); i += 7) {
    const NearestPoint expected = brute_force(points, points[i], i);
    const NearestPoint got = grid.nearest(points[i], i);
    EXPECT_EQ(got.index, expected.index);
    EXPECT_DOUBLE_EQ(got.distance, expected.distance);
  }
}

TEST(PointGrid, FarQueriesAndEmptyGrids) {
  const std::vector<Eigen::Vector3d> one = {{1.0, 2.0, 3.0}};
  const PointGrid grid(one, 1e-3);
  const NearestPoint far = grid.nearest({1e6, -1e6, 0.0});
  EXPECT_EQ(far.index, 0u);
  EXPECT_NEAR(far.distance, (Eigen::Vector3d(1e6, -1e6, 0.0) - one[0]).norm(), 1e-6);
  EXPECT_EQ(grid.nearest(one[0], 0).index, std::numeric_limits<std::size_t>::max());
  const PointGrid empty(std::vector<Eigen::Vector3d>{}, 1.0);
  EXPECT_TRUE(std::isinf(empty.nearest(Eigen::Vector3d::Zero()).distance));
}

TEST(NearestNeighbours, CollinearAndCoincidentPoints) {
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(0.0, 0.0, 0.1 * i * i);  // gaps grow along the line
  const std::vector<double> nn = nearest_neighbour_distances(line);
  EXPECT_NEAR(nn[0], 0.1, 1e-12);
  EXPECT_NEAR(nn[49], 0.1 * (49 * 49 - 48 * 48), 1e-9);
  const std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 1, 1));
  for (const double d : nearest_neighbour_distances(same)) EXPECT_EQ(d, 0.0);
  EXPECT_TRUE(std::isinf(nearest_neighbour_distances(std::vector<Eigen::Vector3d>{{0, 0, 0}})[0]));
}

}  // namespace
}  // namespace ts::sampler
