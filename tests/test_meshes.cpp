#include "tests/test_meshes.h"

#include <cmath>
#include <map>

namespace ts::test {

TriangleMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

TriangleMesh icosphere(double radius, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh m;
  for (auto v : {Eigen::Vector3d(-1, t, 0), Eigen::Vector3d(1, t, 0), Eigen::Vector3d(-1, -t, 0), Eigen::Vector3d(1, -t, 0),
                 Eigen::Vector3d(0, -1, t), Eigen::Vector3d(0, 1, t), Eigen::Vector3d(0, -1, -t), Eigen::Vector3d(0, 1, -t),
                 Eigen::Vector3d(t, 0, -1), Eigen::Vector3d(t, 0, 1), Eigen::Vector3d(-t, 0, -1), Eigen::Vector3d(-t, 0, 1)})
    m.vertices.push_back(v.normalized() * radius);
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized() * radius);
      return mid[key] = static_cast<std::uint32_t>(m.vertices.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (auto [a, b, c] : m.triangles) {
      const auto ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.triangles = std::move(next);
  }
  return m;
}

}  // namespace ts::test
