#pragma once
// Area-uniform random points on a triangle mesh: the seeds of the repulsion sampler and the dense
// probe set that measures its covering radius. Randomness is injected (a seeded std::mt19937_64), so
// a seed fixes every point on every platform: the uniform numbers are built from the generator's raw
// 64-bit output, not from std::uniform_real_distribution, whose algorithm the standard leaves open.
#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "core/mesh.h"

namespace ts::sampler {

// Uniform double in [0, 1) from the top 53 bits of one 64-bit draw.
inline double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// The cumulative area table of a mesh: picks a triangle with probability area / total area by binary
// search, then a point uniformly inside it. Zero-area triangles are never picked.
class AreaTable {
 public:
  // Throws ts::InputError when the mesh has no triangle of positive area.
  explicit AreaTable(const TriangleMesh& mesh);

  double total_area() const { return cumulative_.back(); }  // m^2
  const TriangleMesh& mesh() const { return *mesh_; }

  // The triangle holding the fraction u in [0, 1) of the total area.
  std::uint32_t pick_triangle(double u) const;
  // A uniform point of triangle t from two uniform numbers: with r = sqrt(u1) the barycentric
  // coordinates (1 - r, r (1 - u2), r u2) have the density of a uniform point (pbrt's
  // SampleUniformTriangle; Osada et al. 2002).
  Eigen::Vector3d point_in_triangle(std::uint32_t t, double u1, double u2) const;
  // Unit normal of triangle t (counter-clockwise seen from outside, so outward on a closed mesh).
  Eigen::Vector3d face_normal(std::uint32_t t) const;

 private:
  const TriangleMesh* mesh_;
  std::vector<double> cumulative_;  // m^2: cumulative_[i] = area of triangles 0..i
  std::uint32_t last_positive_ = 0;  // u rounding up to the total lands here
};

struct SurfacePoints {
  std::vector<Eigen::Vector3d> positions;  // m, mesh coordinates
  std::vector<std::uint32_t> triangles;    // index into mesh.triangles of each point's triangle
  std::vector<Eigen::Vector3d> normals;    // unit face normal of that triangle (outward)
};

// `count` independent area-uniform points. Draws exactly three numbers per point from `rng`, in
// point order, so the result depends only on the generator's state.
SurfacePoints sample_surface_points(const TriangleMesh& mesh, std::size_t count, std::mt19937_64& rng);
SurfacePoints sample_surface_points(const AreaTable& table, std::size_t count, std::mt19937_64& rng);

}  // namespace ts::sampler
