#include "sdf/prism_model.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

namespace ts::sdf {
namespace {

using Point = Eigen::Vector3f;

// Primitives slice_tetrahedron emits at height z: none when all four corners lie on one side (a corner
// is above when its height minus z is > 0, as in the shader), 2 for a quad, 1 for a triangle.
int tetrahedron_slice_primitives(const std::array<Point, 4>& v, float z) {
  int above = 0;
  for (const Point& p : v) above += (p.z() - z) > 0.0f ? 1 : 0;
  if (above == 0 || above == 4) return 0;
  return above == 2 ? 2 : 1;
}

// The shader's 3-tetrahedron split of the triangular prism abc-a2b2c2.
int triangular_prism_slice_primitives(const Point& a, const Point& b, const Point& c, const Point& a2,
                                      const Point& b2, const Point& c2, float z) {
  return tetrahedron_slice_primitives({a, b, c, a2}, z) + tetrahedron_slice_primitives({b, c, a2, b2}, z) +
         tetrahedron_slice_primitives({c, a2, b2, c2}, z);
}

// Area of the prism's base polygon (3 or 4 corners, convex, in the triangle's plane) [voxels^2].
double base_area(const std::array<Point, 4>& corner, int corners) {
  Eigen::Vector3d twice_area = Eigen::Vector3d::Zero();
  for (int i = 1; i + 1 < corners; ++i) {
    twice_area += (corner[i] - corner[0]).cast<double>().cross((corner[i + 1] - corner[0]).cast<double>());
  }
  return 0.5 * twice_area.norm();
}

}  // namespace

PrismWorkModel model_prism_work(std::span<const gpu::layout::SdfPrism> prisms,
                                std::span<const std::uint32_t> drawn, int z_layers) {
  PrismWorkModel model;
  for (std::uint32_t t : drawn) {
    const gpu::layout::SdfPrism& prism = prisms[t];
    const int corners = static_cast<int>(prism.corner[0].w);
    const Point offset =
        Point(prism.normal_margin.x, prism.normal_margin.y, prism.normal_margin.z) * prism.normal_margin.w;
    std::array<Point, 4> base, lo, hi;
    float zmin = 1e30f, zmax = -1e30f;
    for (int i = 0; i < 4; ++i) {
      base[i] = Point(prism.corner[i].x, prism.corner[i].y, prism.corner[i].z);
      lo[i] = base[i] - offset;
      hi[i] = base[i] + offset;
      if (i < corners) {
        zmin = std::min({zmin, lo[i].z(), hi[i].z()});
        zmax = std::max({zmax, lo[i].z(), hi[i].z()});
      }
    }
    model.volume += base_area(base, corners) * 2.0 * prism.normal_margin.w;
    const int first = std::max(0, static_cast<int>(std::ceil(zmin)));
    const int last = std::min(z_layers - 1, static_cast<int>(std::floor(zmax)));
    for (int k = first; k <= last; ++k) {
      const float z = static_cast<float>(k);
      model.primitives += triangular_prism_slice_primitives(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], z);
      if (corners == 4) {
        model.primitives += triangular_prism_slice_primitives(lo[0], lo[2], lo[3], hi[0], hi[2], hi[3], z);
      }
    }
  }
  return model;
}

}  // namespace ts::sdf
