#pragma once
// How good a set of surface samples is (docs/notes: "Mesh sampling"): spacing regularity from
// nearest-neighbour distances (relative radius rho, Lagae & Dutre 2008; coefficient of variation) and
// the covering radius, the largest hole, measured against a dense area-uniform probe set. The
// sampler's hole-closing step calls measure_coverage() alone each round and injects particles at the
// worst uncovered points it returns.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/mesh.h"

namespace ts::sampler {

// Covering radius of a hexagonal lattice over its spacing: the deep holes are the centroids of the
// equilateral triangles, at s / sqrt(3) from their three corners.
inline const double kHexCoveringOverSpacing = 1.0 / std::sqrt(3.0);

// d_hex = sqrt(2 A / (sqrt(3) N)) [m]: the spacing of a hexagonal lattice of N points on area A [m^2]
// (each point owns a hexagon of area sqrt(3)/2 s^2).
double hex_spacing(double area, std::size_t count);

// Particles needed for a covering radius c [m] on area A [m^2]. A set whose holes are c deep at
// spacing d_hex has c = k d_hex, k = covering_over_spacing; so d_hex = c / k and, from the definition
// of d_hex, N = 2 A / (sqrt(3) d_hex^2) = 2 A k^2 / (sqrt(3) c^2). A perfect hexagonal lattice has
// k = 1/sqrt(3): covering a surface with particle spheres of radius r (c <= r, no leaks whatever the
// grain size) needs spacing sqrt(3) r and N = 2 A / (3 sqrt(3) r^2). Relaxed repulsion sets reach
// k = 0.66-0.71 (formulas.md), so pass that k to budget for a real sampler. Returns a real number;
// round up.
double particles_for_covering_radius(double area, double covering_radius,
                                     double covering_over_spacing = kHexCoveringOverSpacing);

struct CoverageSettings {
  std::size_t probes = 1'000'000;  // area-uniform surface points the distance is maximised over
  std::uint64_t seed = 1;          // fixes the probes: the same seed gives the same result
  std::size_t worst_k = 0;         // how many uncovered points to return
  // Returned points are well separated: each lies at least separation * depth from every deeper one
  // returned before it (depth = its distance to the nearest sample), so one hole yields one point.
  double separation = 1.0;
  double min_depth = 0.0;  // m: holes no deeper than this are not returned
};

struct UncoveredPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // m, on the surface
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // unit outward face normal there
  std::uint32_t triangle = 0;
  double depth = 0.0;  // m, distance to the nearest sample
};

struct CoverageResult {
  double covering_radius = 0.0;        // m: max over the probes of the distance to the nearest sample
  UncoveredPoint deepest;              // the probe that attains covering_radius
  std::vector<UncoveredPoint> worst;   // up to worst_k, deepest first, well separated
  std::size_t probes = 0;
};

// Probes are generated in fixed-size chunks, each from its own generator seeded from (seed, chunk),
// and queried in parallel (TBB): the result does not depend on the thread count. Samples must be non-
// empty; they need not lie on the surface.
CoverageResult measure_coverage(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> samples,
                                const CoverageSettings& settings);
CoverageResult measure_coverage(const TriangleMesh& mesh, std::span<const Eigen::Vector3f> samples,
                                const CoverageSettings& settings);

// Distance from each sample to its nearest other sample [m] (infinity for a lone sample). TBB-parallel.
std::vector<double> nearest_neighbour_distances(std::span<const Eigen::Vector3d> samples);

struct SpacingStatistics {
  double d_hex = 0.0;            // m
  double relative_radius = 0.0;  // rho = min NN / d_hex (1 for a perfect hexagonal lattice)
  double mean_nn = 0.0;          // m
  double cv_nn = 0.0;            // std(NN) / mean(NN), population standard deviation
};
// From nearest-neighbour distances; fewer than two samples give all zeros except d_hex.
SpacingStatistics spacing_statistics(double area, std::span<const Eigen::Vector3d> samples);

// The largest distance from a sample to the mesh surface [m]: the exact |phi| of the mesh, measured
// independently of any voxelised field the samples were projected with. TBB-parallel.
double max_distance_to_surface(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> samples);

struct SamplingQuality {
  std::size_t count = 0;
  double area = 0.0;              // m^2
  double d_hex = 0.0;             // m
  double relative_radius = 0.0;   // rho = min NN / d_hex
  double mean_nn = 0.0;           // m
  double cv_nn = 0.0;
  double covering_radius = 0.0;   // m
  double covering_over_r = 0.0;   // c / particle radius; <= 1: the particle spheres cover the surface
  double max_abs_phi = 0.0;       // m
  Eigen::Vector3d worst_uncovered_point = Eigen::Vector3d::Zero();  // m, where the covering radius is attained
};

// Every metric at once. particle_radius [m] > 0.
SamplingQuality measure_quality(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> samples,
                                double particle_radius, const CoverageSettings& settings = {});

}  // namespace ts::sampler
