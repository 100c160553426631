#include "sampler/interior_fill.h"

#include <tbb/parallel_for.h>

#include <array>
#include <cmath>

namespace ts::sampler {

double interior_lattice_density(double radius) { return 1.0 / (4.0 * std::sqrt(2.0) * radius * radius * radius); }

std::vector<Eigen::Vector3d> fill_interior(const sdf::ExactDistance& exact, const Aabb& box,
                                           const Eigen::Vector3d& lattice_origin, double radius,
                                           sdf::SignMethod sign) {
  const double edge = 2.0 * std::sqrt(2.0) * radius;  // cubic cell of the FCC lattice
  constexpr std::array<std::array<double, 3>, 4> basis = {{{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}}};
  // Kept points are at least r inside, so only the box shrunk by r can hold them.
  const Eigen::Vector3d lo = box.min.array() + radius, hi = box.max.array() - radius;
  if ((hi.array() < lo.array()).any()) return {};
  Eigen::Vector3i first, last;
  for (int a = 0; a < 3; ++a) {
    first[a] = static_cast<int>(std::floor((lo[a] - lattice_origin[a]) / edge)) - 1;
    last[a] = static_cast<int>(std::ceil((hi[a] - lattice_origin[a]) / edge));
  }
  const int layers = last.z() - first.z() + 1;
  std::vector<std::vector<Eigen::Vector3d>> kept(static_cast<std::size_t>(layers));
  tbb::parallel_for(0, layers, [&](int layer) {
    const int k = first.z() + layer;
    for (int j = first.y(); j <= last.y(); ++j) {
      for (int i = first.x(); i <= last.x(); ++i) {
        for (const auto& b : basis) {
          const Eigen::Vector3d p = lattice_origin + edge * Eigen::Vector3d(i + b[0], j + b[1], k + b[2]);
          if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
          if (exact.signed_distance(p, sign) <= -radius) kept[static_cast<std::size_t>(layer)].push_back(p);
        }
      }
    }
  });
  std::vector<Eigen::Vector3d> out;
  for (const auto& layer : kept) out.insert(out.end(), layer.begin(), layer.end());
  return out;
}

}  // namespace ts::sampler
