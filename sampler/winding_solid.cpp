#include "sampler/winding_solid.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/error.h"

namespace ts::sampler {
namespace {

// Volume integrals relative to a reference point: m0 = V, m1 = integral of x, m2 = integral of x x^T.
struct Moments {
  double m0 = 0.0;
  Eigen::Vector3d m1 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d m2 = Eigen::Matrix3d::Zero();

  // `fraction` of a cube of edge `edge` centred at c, its mass spread as the whole cube's is.
  void add_cube(const Eigen::Vector3d& c, double edge, double fraction) {
    const double v = fraction * edge * edge * edge;
    m0 += v;
    m1 += v * c;
    m2 += v * (c * c.transpose() + (edge * edge / 12.0) * Eigen::Matrix3d::Identity());
  }
  void add(const Moments& o) {
    m0 += o.m0;
    m1 += o.m1;
    m2 += o.m2;
  }
};

struct Node {
  Eigen::Vector3d centre;  // relative to the reference point
  double edge;
};

bool inside(double winding) { return std::abs(winding) >= 0.5; }
constexpr double kIntegralWinding = 0.02;

// What one cell contributes, or that it must be split.
struct Visit {
  Moments moments;
  bool split = false;
  bool boundary = false;
};

Visit visit(const sdf::ExactDistance& exact, const Eigen::Vector3d& reference, const Node& node, double finest) {
  Visit out;
  const Eigen::Vector3d world = reference + node.centre;
  const double distance = exact.closest(world).distance;
  const double half_diagonal = 0.5 * std::sqrt(3.0) * node.edge;
  const double winding = exact.winding_number(world);
  const bool centre_inside = inside(winding);
  const bool is_finest = node.edge <= 1.0000001 * finest;
  if (distance > half_diagonal) {
    // The mesh does not cross the cell; the |w| = 1/2 surface over a hole still may, where w is
    // fractional: there the corners must agree too. (Off a closed surface w is an integer, up to
    // the fast evaluation's error of about 1e-2.)
    const bool integral = std::abs(std::abs(winding) - std::round(std::abs(winding))) <= kIntegralWinding;
    bool uniform = true;
    for (int k = 0; k < 8 && uniform && !is_finest && !integral; ++k) {
      const Eigen::Vector3d corner(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
      uniform = inside(exact.winding_number(world + node.edge * corner)) == centre_inside;
    }
    if (uniform) {
      if (centre_inside) out.moments.add_cube(node.centre, node.edge, 1.0);
      return out;
    }
    if (!is_finest) {
      out.split = true;
      return out;
    }
  }
  if (!is_finest) {
    out.split = true;
    return out;
  }
  out.boundary = true;
  const double phi = centre_inside ? -distance : distance;
  const double fraction = std::clamp(0.5 - phi / node.edge, 0.0, 1.0);
  if (fraction > 0.0) out.moments.add_cube(node.centre, node.edge, fraction);
  return out;
}

MassProperties from_moments(const Moments& m, const Eigen::Vector3d& reference, double density) {
  MassProperties out;
  out.density = density;
  out.volume = m.m0;
  out.mass = density * m.m0;
  const Eigen::Vector3d c = m.m1 / m.m0;  // relative to the reference point
  const Eigen::Matrix3d second = m.m2 - m.m0 * c * c.transpose();  // integral of (x - c)(x - c)^T
  out.inertia = density * (second.trace() * Eigen::Matrix3d::Identity() - second);
  out.inertia = 0.5 * (out.inertia + out.inertia.transpose());
  out.center_of_mass = reference + c;
  const PrincipalFrame principal = principal_frame(out.inertia);
  out.principal_moments = principal.moments;
  out.principal_axes = principal.axes;
  return out;
}

}  // namespace

WindingSolid winding_mass_properties(const TriangleMesh& mesh, const sdf::ExactDistance& exact, double density,
                                     double cell) {
  if (!(density > 0.0)) throw InputError(fmt::format("density must be positive (got {})", density));
  const Aabb box = bounding_box(mesh);
  const double longest = box.size().maxCoeff();
  if (!(longest > 0.0) || !std::isfinite(longest)) throw InputError("the mesh has an empty or non-finite bounding box");
  WindingSolid out;
  out.cell = cell > 0.0 ? cell : longest / kDefaultWindingCellsAlongLongestSide;
  // A root cube of 2^k finest cells around the box, one cell of margin on each side.
  double root = out.cell;
  while (root < longest + 2.0 * out.cell) root *= 2.0;
  const Eigen::Vector3d reference = box.center();

  // Breadth first: every level's cells are visited in parallel and summed in their fixed order,
  // so the result does not depend on the thread schedule.
  Moments total;
  std::vector<Node> level{{Eigen::Vector3d::Zero(), root}};
  std::vector<Visit> visits;
  while (!level.empty()) {
    visits.assign(level.size(), Visit{});
    tbb::parallel_for(std::size_t{0}, level.size(),
                      [&](std::size_t i) { visits[i] = visit(exact, reference, level[i], out.cell); });
    std::vector<Node> next;
    for (std::size_t i = 0; i < level.size(); ++i) {
      total.add(visits[i].moments);
      out.boundary_cells += visits[i].boundary ? 1 : 0;
      if (!visits[i].split) continue;
      const double half = 0.5 * level[i].edge;
      for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d offset(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
        next.push_back({level[i].centre + half * offset, half});
      }
    }
    level = std::move(next);
  }
  if (!(total.m0 > 0.0)) {
    throw InputError("the mesh encloses no volume: no point has a winding number of 1/2 or more");
  }
  out.mass = from_moments(total, reference, density);
  return out;
}

}  // namespace ts::sampler
