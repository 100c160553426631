#include "core/primitives.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>

namespace ts {
namespace {

// Appends a grid of quads (two triangles each) between rows of vertex indices, wrapping as asked.
void add_quad(TriangleMesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  m.triangles.push_back({a, b, c});
  m.triangles.push_back({a, c, d});
}

// A closed tube around a closed curve: rings of n_around vertices at each of n_along stations.
TriangleMesh tube(const std::vector<Eigen::Vector3d>& centres, const std::vector<Eigen::Vector3d>& normals,
                  const std::vector<Eigen::Vector3d>& binormals, double radius, int n_around) {
  TriangleMesh m;
  const int n_along = static_cast<int>(centres.size());
  for (int i = 0; i < n_along; ++i) {
    for (int j = 0; j < n_around; ++j) {
      const double phi = 2.0 * M_PI * j / n_around;
      m.vertices.push_back(centres[static_cast<std::size_t>(i)] +
                           radius * (std::cos(phi) * normals[static_cast<std::size_t>(i)] +
                                     std::sin(phi) * binormals[static_cast<std::size_t>(i)]));
    }
  }
  auto index = [&](int i, int j) {
    return static_cast<std::uint32_t>(((i % n_along + n_along) % n_along) * n_around + (j % n_around));
  };
  for (int i = 0; i < n_along; ++i)
    for (int j = 0; j < n_around; ++j) add_quad(m, index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1));
  return m;
}

}  // namespace

TriangleMesh make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) add_quad(m, q[0], q[1], q[2], q[3]);
  return m;
}

TriangleMesh make_box(const Eigen::Vector3d& size) { return make_box(-0.5 * size, 0.5 * size); }

TriangleMesh make_icosphere(double radius, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh m;
  for (const auto& v : {Eigen::Vector3d(-1, t, 0), Eigen::Vector3d(1, t, 0), Eigen::Vector3d(-1, -t, 0),
                        Eigen::Vector3d(1, -t, 0), Eigen::Vector3d(0, -1, t), Eigen::Vector3d(0, 1, t),
                        Eigen::Vector3d(0, -1, -t), Eigen::Vector3d(0, 1, -t), Eigen::Vector3d(t, 0, -1),
                        Eigen::Vector3d(t, 0, 1), Eigen::Vector3d(-t, 0, -1), Eigen::Vector3d(-t, 0, 1)})
    m.vertices.push_back(v.normalized() * radius);
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      if (auto it = midpoints.find(key); it != midpoints.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized() * radius);
      return midpoints[key] = static_cast<std::uint32_t>(m.vertices.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& [a, b, c] : m.triangles) {
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

TriangleMesh make_torus(double major_radius, double minor_radius, int nu, int nv) {
  std::vector<Eigen::Vector3d> centres, normals, binormals;
  for (int i = 0; i < nu; ++i) {
    const double u = 2.0 * M_PI * i / nu;
    const Eigen::Vector3d radial(std::cos(u), std::sin(u), 0.0);
    centres.push_back(major_radius * radial);
    normals.push_back(radial);
    binormals.push_back(Eigen::Vector3d::UnitZ());
  }
  return tube(centres, normals, binormals, minor_radius, nv);
}

TriangleMesh make_trefoil_tube(double scale, double tube_radius, int n_along, int n_around) {
  auto curve = [&](double t) -> Eigen::Vector3d {  // explicit type: no Eigen expression over a temporary
    return scale * Eigen::Vector3d(std::sin(t) + 2.0 * std::sin(2.0 * t), std::cos(t) - 2.0 * std::cos(2.0 * t),
                                   -std::sin(3.0 * t));
  };
  std::vector<Eigen::Vector3d> centres, tangents;
  for (int i = 0; i < n_along; ++i) {
    const double t = 2.0 * M_PI * i / n_along, h = 1e-5;
    centres.push_back(curve(t));
    tangents.push_back((curve(t + h) - curve(t - h)).normalized());
  }
  // Rotation-minimising frames by double reflection (Wang et al. 2008), then the leftover twist at the
  // seam is spread evenly so that the last ring meets the first.
  std::vector<Eigen::Vector3d> normals(static_cast<std::size_t>(n_along));
  normals[0] = tangents[0].unitOrthogonal();
  for (std::size_t i = 0; i + 1 < normals.size() + 1; ++i) {
    const std::size_t j = (i + 1) % normals.size();
    const Eigen::Vector3d v1 = centres[j] - centres[i];
    const double c1 = v1.squaredNorm();
    const Eigen::Vector3d r_l = normals[i] - (2.0 / c1) * v1.dot(normals[i]) * v1;
    const Eigen::Vector3d t_l = tangents[i] - (2.0 / c1) * v1.dot(tangents[i]) * v1;
    const Eigen::Vector3d v2 = tangents[j] - t_l;
    const double c2 = v2.squaredNorm();
    const Eigen::Vector3d next = c2 > 0 ? Eigen::Vector3d(r_l - (2.0 / c2) * v2.dot(r_l) * v2) : r_l;
    if (j == 0) {
      // Angle between the transported frame and the first one, about the tangent.
      const Eigen::Vector3d b0 = tangents[0].cross(normals[0]);
      const double twist = std::atan2(next.dot(b0), next.dot(normals[0]));
      for (std::size_t k = 0; k < normals.size(); ++k) {
        const double angle = -twist * static_cast<double>(k) / static_cast<double>(normals.size());
        normals[k] = Eigen::AngleAxisd(angle, tangents[k]) * normals[k];
      }
      break;
    }
    normals[j] = (next - next.dot(tangents[j]) * tangents[j]).normalized();
  }
  std::vector<Eigen::Vector3d> binormals;
  // (normal, binormal, tangent) left-handed like the torus's frames, so the quads face outward.
  for (std::size_t k = 0; k < normals.size(); ++k) binormals.push_back(normals[k].cross(tangents[k]));
  return tube(centres, normals, binormals, tube_radius, n_around);
}

TriangleMesh make_plate(double sx, double sy, double thickness, int nx, int ny) {
  TriangleMesh m;
  const double hx = sx / 2, hy = sy / 2, hz = thickness / 2;
  // Top and bottom grids share their rims; the four sides join the rims.
  auto grid_index = [&](int side, int i, int j) { return static_cast<std::uint32_t>(side * (nx + 1) * (ny + 1) + j * (nx + 1) + i); };
  for (int side = 0; side < 2; ++side)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.vertices.emplace_back(-hx + sx * i / nx, -hy + sy * j / ny, side ? hz : -hz);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      add_quad(m, grid_index(1, i, j), grid_index(1, i + 1, j), grid_index(1, i + 1, j + 1), grid_index(1, i, j + 1));
      add_quad(m, grid_index(0, i, j), grid_index(0, i, j + 1), grid_index(0, i + 1, j + 1), grid_index(0, i + 1, j));
    }
  for (int i = 0; i < nx; ++i) {
    add_quad(m, grid_index(0, i, 0), grid_index(0, i + 1, 0), grid_index(1, i + 1, 0), grid_index(1, i, 0));
    add_quad(m, grid_index(0, i + 1, ny), grid_index(0, i, ny), grid_index(1, i, ny), grid_index(1, i + 1, ny));
  }
  for (int j = 0; j < ny; ++j) {
    add_quad(m, grid_index(0, 0, j + 1), grid_index(0, 0, j), grid_index(1, 0, j), grid_index(1, 0, j + 1));
    add_quad(m, grid_index(0, nx, j), grid_index(0, nx, j + 1), grid_index(1, nx, j + 1), grid_index(1, nx, j));
  }
  return m;
}

}  // namespace ts
