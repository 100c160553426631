#pragma once
// The coverage certificate of sampler/gpu_coverage_certificate.h, computed on the CPU in double
// precision: the same midpoint subdivision, the same fate for each sub-triangle (covered when one
// ball of the radius holds its three corners, split, or final at the floor), the same covering bound
// and witnesses, in the same CoverageCertificate. Each triangle is refined depth first on its own
// (TBB over the triangles), so memory holds only the uncovered pieces: no tiles, no sub-triangle
// budget. It is the GPU certifier's twin for a software GL device, where the GPU path is slow and
// bounded by the largest storage block. docs/coverage-certificate.md ("The CPU certifier") gives the
// passes, the double-precision margin and why the result stays conservative.
#include <Eigen/Core>
#include <span>
#include <vector>

#include "core/mesh.h"
#include "sampler/gpu_coverage_certificate.h"

namespace ts::sampler {

class CpuCoverageCertifier {
 public:
  // Takes the triangles relative to the centre of the mesh's bounding box. `mesh` must outlive the
  // certifier. Throws InputError for a vertex that is not finite.
  explicit CpuCoverageCertifier(const TriangleMesh& mesh);

  // Certifies balls of `radius` [m] > 0 about `centres` (m, mesh coordinates, at least one, finite):
  // the particles as a body stores them. Same input: same result, bit for bit, whatever the thread
  // count. `settings.max_shells` and `settings.max_subtriangles` do not apply (the neighbour search is
  // exact, and there is no level to budget): `tiles` is 1, `budget_reached` false.
  CoverageCertificate certify(std::span<const Eigen::Vector3f> centres, double radius,
                              const CertificateSettings& settings = {});

 private:
  // A mesh triangle in the local frame: the sub-triangle corners are corner + a edge1 + b edge2.
  struct LocalTriangle {
    Eigen::Vector3d corner, edge1, edge2;  // m
    double longest = 0.0;                  // m, its longest edge
  };
  class Pass;  // one refinement of some triangles under fixed rules (in the .cpp)

  const TriangleMesh& mesh_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // m, centre of the mesh's bounding box
  double mesh_extent_ = 0.0;                          // m, largest distance of a vertex from it
  std::vector<LocalTriangle> triangles_;
};

}  // namespace ts::sampler
