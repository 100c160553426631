#include "core/mass_properties.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "core/error.h"

namespace ts {
namespace {

// Integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the enclosed volume (Eberly's
// subexpressions), with every vertex taken relative to `origin` so that a mesh far from the origin
// keeps its precision.
std::array<double, 10> volume_integrals(const TriangleMesh& mesh, const Eigen::Vector3d& origin) {
  auto subexpressions = [](double w0, double w1, double w2, double& f1, double& f2, double& f3, double& g0,
                           double& g1, double& g2) {
    const double temp0 = w0 + w1;
    f1 = temp0 + w2;
    const double temp1 = w0 * w0;
    const double temp2 = temp1 + w1 * temp0;
    f2 = temp2 + w2 * f1;
    f3 = w0 * temp1 + w1 * temp2 + w2 * f2;
    g0 = f2 + w0 * (f1 + w0);
    g1 = f2 + w1 * (f1 + w1);
    g2 = f2 + w2 * (f1 + w2);
  };
  std::array<double, 10> integral{};
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d p0 = mesh.vertices[t[0]] - origin, p1 = mesh.vertices[t[1]] - origin,
                          p2 = mesh.vertices[t[2]] - origin;
    const Eigen::Vector3d d = (p1 - p0).cross(p2 - p0);
    double f1x, f2x, f3x, g0x, g1x, g2x, f1y, f2y, f3y, g0y, g1y, g2y, f1z, f2z, f3z, g0z, g1z, g2z;
    subexpressions(p0.x(), p1.x(), p2.x(), f1x, f2x, f3x, g0x, g1x, g2x);
    subexpressions(p0.y(), p1.y(), p2.y(), f1y, f2y, f3y, g0y, g1y, g2y);
    subexpressions(p0.z(), p1.z(), p2.z(), f1z, f2z, f3z, g0z, g1z, g2z);
    integral[0] += d.x() * f1x;
    integral[1] += d.x() * f2x;
    integral[2] += d.y() * f2y;
    integral[3] += d.z() * f2z;
    integral[4] += d.x() * f3x;
    integral[5] += d.y() * f3y;
    integral[6] += d.z() * f3z;
    integral[7] += d.x() * (p0.y() * g0x + p1.y() * g1x + p2.y() * g2x);
    integral[8] += d.y() * (p0.z() * g0y + p1.z() * g1y + p2.z() * g2y);
    integral[9] += d.z() * (p0.x() * g0z + p1.x() * g1z + p2.x() * g2z);
  }
  static constexpr std::array<double, 10> scale{1.0 / 6,   1.0 / 24,  1.0 / 24,  1.0 / 24,  1.0 / 60,
                                                1.0 / 60,  1.0 / 60,  1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (std::size_t k = 0; k < 10; ++k) integral[k] *= scale[k];
  return integral;
}

// Edges not cancelled by an edge running the other way. The divergence theorem needs the surface to
// bound a region: every directed edge matched by its reverse (holes and flipped faces break this;
// two solids sharing an edge do not).
std::size_t unmatched_edges(const TriangleMesh& mesh) {
  std::unordered_map<std::uint64_t, int> balance;
  balance.reserve(3 * mesh.triangle_count());
  for (const auto& t : mesh.triangles) {
    for (std::size_t e = 0; e < 3; ++e) {
      const std::uint32_t u = t[e], v = t[(e + 1) % 3];
      if (u == v) continue;
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(u, v)) << 32) | std::max(u, v);
      balance[key] += u < v ? 1 : -1;
    }
  }
  std::size_t unmatched = 0;
  for (const auto& [key, b] : balance) unmatched += b != 0 ? 1 : 0;
  return unmatched;
}

Eigen::Vector3d reference_point(const TriangleMesh& mesh) { return bounding_box(mesh).center(); }

}  // namespace

double signed_volume(const TriangleMesh& mesh) {
  if (mesh.empty()) return 0.0;
  return volume_integrals(mesh, reference_point(mesh))[0];
}

PrincipalFrame principal_frame(const Eigen::Matrix3d& inertia) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(inertia);
  PrincipalFrame frame{eigen.eigenvalues(), eigen.eigenvectors()};
  if (frame.axes.determinant() < 0.0) frame.axes.col(2) *= -1.0;
  return frame;
}

MassProperties compute_mass_properties(const TriangleMesh& mesh, double density) {
  if (!(density > 0.0) || !std::isfinite(density)) {
    throw InputError(fmt::format("density must be positive (got {} kg/m^3)", density));
  }
  if (mesh.empty()) throw InputError("mass properties of an empty mesh");
  if (const std::size_t open = unmatched_edges(mesh); open > 0) {
    throw InputError(fmt::format("mass properties need a closed, consistently oriented mesh: {} edges are open or "
                                 "traversed the same way by their two triangles (holes or flipped faces)",
                                 open));
  }
  const Eigen::Vector3d origin = reference_point(mesh);
  const auto integral = volume_integrals(mesh, origin);
  const double volume = integral[0];
  const double size = bounding_box(mesh).size().maxCoeff();
  if (volume < 0.0) {
    throw InputError(fmt::format("the mesh is inside out (signed volume {:.6g} m^3): its triangles face inward", volume));
  }
  if (!(volume > 1e-12 * size * size * size)) {
    throw InputError(fmt::format("the mesh encloses no volume ({:.6g} m^3): it is flat or degenerate", volume));
  }
  MassProperties out;
  out.density = density;
  out.volume = volume;
  out.mass = density * volume;
  const Eigen::Vector3d c(integral[1] / volume, integral[2] / volume, integral[3] / volume);  // relative to origin
  Eigen::Matrix3d i;
  i(0, 0) = integral[5] + integral[6] - volume * (c.y() * c.y() + c.z() * c.z());
  i(1, 1) = integral[4] + integral[6] - volume * (c.z() * c.z() + c.x() * c.x());
  i(2, 2) = integral[4] + integral[5] - volume * (c.x() * c.x() + c.y() * c.y());
  i(0, 1) = i(1, 0) = -(integral[7] - volume * c.x() * c.y());
  i(1, 2) = i(2, 1) = -(integral[8] - volume * c.y() * c.z());
  i(0, 2) = i(2, 0) = -(integral[9] - volume * c.z() * c.x());
  out.inertia = density * i;
  out.center_of_mass = origin + c;
  const PrincipalFrame principal = principal_frame(out.inertia);
  out.principal_moments = principal.moments;
  out.principal_axes = principal.axes;
  return out;
}

}  // namespace ts
