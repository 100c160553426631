#include "sdf/winding_number.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ts::sdf {
namespace {

constexpr std::uint32_t kLeafSize = 8;  // triangles per leaf: below this, opening a node costs more than summing

}  // namespace

// A small patch of vector area dA at x subtends dA . g(x - p), g(r) = r / |r|^3. About the centre,
// x - p = d + e and g(d + e) = g(d) + J e + H[e, e] / 2 with
//   J_ij = delta_ij / |d|^3 - 3 d_i d_j / |d|^5,
//   H_ijk = -3 (delta_ij d_k + delta_ik d_j + delta_jk d_i) / |d|^5 + 15 d_i d_j d_k / |d|^7,
// integrated over the node's area: the moments stored in each node.
double FastWindingNumber::far_field(const Node& node, const Eigen::Vector3d& d, double d2) {
  const double inv_d3 = 1.0 / (d2 * std::sqrt(d2)), inv_d5 = inv_d3 / d2, inv_d7 = inv_d5 / d2;
  const Eigen::Matrix3d& m1 = node.first_moment;
  double zeroth = node.vector_area.dot(d) * inv_d3;
  double first = m1.trace() * inv_d3 - 3.0 * d.dot(m1 * d) * inv_d5;
  double diagonal = 0.0, traces = 0.0, cubic = 0.0;  // sum_ik d_k T_iik, sum_i d_i T_ijj, sum d_i d_j d_k T_ijk
  for (int i = 0; i < 3; ++i) {
    const Eigen::Matrix3d& t = node.second_moment[static_cast<std::size_t>(i)];
    diagonal += t.row(i).dot(d);
    traces += d[i] * t.trace();
    cubic += d[i] * d.dot(t * d);
  }
  const double second = 0.5 * (-3.0 * (2.0 * diagonal + traces) * inv_d5 + 15.0 * cubic * inv_d7);
  return zeroth + first + second;
}

double solid_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  // atan2(0, 0) is 0 in IEEE arithmetic: a degenerate triangle, or p on a vertex, adds nothing.
  return 2.0 * std::atan2(numerator, denominator);
}

double winding_number_direct(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  double total = 0.0;
  for (const auto& t : mesh.triangles) {
    total += solid_angle(mesh.vertices[t[0]] - p, mesh.vertices[t[1]] - p, mesh.vertices[t[2]] - p);
  }
  return total / (4.0 * std::numbers::pi);
}

FastWindingNumber::FastWindingNumber(const TriangleMesh& mesh, double accuracy)
    : accuracy_squared_(accuracy * accuracy) {
  const auto n = static_cast<std::uint32_t>(mesh.triangle_count());
  corners_.resize(n);
  std::vector<Eigen::Vector3d> centroids(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) corners_[t][static_cast<std::size_t>(k)] = mesh.vertices[mesh.triangles[t][static_cast<std::size_t>(k)]];
    centroids[t] = (corners_[t][0] + corners_[t][1] + corners_[t][2]) / 3.0;
  }
  order_.resize(n);
  for (std::uint32_t t = 0; t < n; ++t) order_[t] = t;
  if (n > 0) {
    nodes_.reserve(2 * (n / kLeafSize + 1));
    build(0, n, centroids);
  }
  // Leaves read their triangles in BVH order.
  std::vector<std::array<Eigen::Vector3d, 3>> sorted(n);
  for (std::uint32_t i = 0; i < n; ++i) sorted[i] = corners_[order_[i]];
  corners_ = std::move(sorted);
}

std::uint32_t FastWindingNumber::build(std::uint32_t first, std::uint32_t count,
                                       std::vector<Eigen::Vector3d>& centroids) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.first = first;
  node.count = count;
  double area = 0.0;
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero(), plain = Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY);
  for (std::uint32_t i = first; i < first + count; ++i) {
    const auto& c = corners_[order_[i]];
    const Eigen::Vector3d twice_area = (c[1] - c[0]).cross(c[2] - c[0]);
    node.vector_area += 0.5 * twice_area;
    const double a = 0.5 * twice_area.norm();
    area += a;
    weighted += a * centroids[order_[i]];
    plain += centroids[order_[i]];
    lo = lo.cwiseMin(centroids[order_[i]]);
    hi = hi.cwiseMax(centroids[order_[i]]);
  }
  // A node of only degenerate triangles has no area to weight by; its plain centroid is as good.
  node.centre = area > 0.0 ? Eigen::Vector3d(weighted / area) : Eigen::Vector3d(plain / count);
  for (std::uint32_t i = first; i < first + count; ++i) {
    const auto& c = corners_[order_[i]];
    const Eigen::Vector3d vector_area = 0.5 * (c[1] - c[0]).cross(c[2] - c[0]);
    const Eigen::Vector3d offset = centroids[order_[i]] - node.centre;
    node.first_moment += vector_area * offset.transpose();
    // A triangle's covariance about its centroid is the sum of its corners' outer products / 12.
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto& v : c) covariance += (v - centroids[order_[i]]) * (v - centroids[order_[i]]).transpose();
    const Eigen::Matrix3d spread = offset * offset.transpose() + covariance / 12.0;
    for (int k = 0; k < 3; ++k) node.second_moment[static_cast<std::size_t>(k)] += vector_area[k] * spread;
    for (const auto& v : c) node.radius = std::max(node.radius, (v - node.centre).norm());
  }
  if (count > kLeafSize) {
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const std::uint32_t half = count / 2;
    std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                     [&](std::uint32_t x, std::uint32_t y) { return centroids[x][axis] < centroids[y][axis]; });
    node.count = 0;
    node.left = build(first, half, centroids);
    node.right = build(first + half, count - half, centroids);
  }
  nodes_[index] = node;
  return index;
}

double FastWindingNumber::operator()(const Eigen::Vector3d& p) const {
  if (nodes_.empty()) return 0.0;
  double total = 0.0;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    const Eigen::Vector3d d = node.centre - p;
    const double d2 = d.squaredNorm();
    if (d2 > accuracy_squared_ * node.radius * node.radius) {
      total += far_field(node, d, d2);
    } else if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const auto& c = corners_[i];
        total += solid_angle(c[0] - p, c[1] - p, c[2] - p);
      }
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
  return total / (4.0 * std::numbers::pi);
}

std::vector<double> FastWindingNumber::evaluate(const std::vector<Eigen::Vector3d>& points) const {
  std::vector<double> out(points.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) out[i] = (*this)(points[i]);
  });
  return out;
}

}  // namespace ts::sdf
