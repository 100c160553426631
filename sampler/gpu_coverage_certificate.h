#pragma once
// A conservative coverage certificate, computed on the GPU: does the union of the balls of radius r
// about the particle centres hold every point of every triangle of the mesh? Each triangle is split
// by midpoints, level after level, until each piece is proven covered (one ball holds its three
// corners, and balls are convex) or reaches a floor; what is left is reported as uncovered, with
// positions and depths. Alongside, an upper bound of the covering radius c = max over the surface of
// the distance to the nearest centre (the certified figure, where random probes give a lower one) and
// a lower bound from the points it evaluated. The argument, the floor and the float margin are in
// docs/coverage-certificate.md.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/hash_grid.h"

namespace ts::sampler {

struct CertificateSettings {
  // A sub-triangle whose longest edge is at most radius / floor_divisor is not split further: it is
  // final, covered or not. The bound is then within max(radius, c) / floor_divisor of c.
  double floor_divisor = 64.0;
  // Once some point is proven uncovered (the verdict is known), partly covered sub-triangles stop at
  // radius / hole_divisor: holes are still located to that size, at a fraction of the work.
  double hole_divisor = 16.0;
  // The neighbour search visits at most this many shells of grid cells (cell = radius) around a
  // sub-triangle; one that finds no centre there is bounded on the CPU (exact nearest centre).
  int max_shells = 8;
  // Sub-triangles one level may hand to the next, which bounds the certificate's GPU memory (8M take
  // about 330 MB; at most about 1.07e9, so that a level's children, four each, count in 32 bits).
  // Triangles are certified in tiles (ranges of triangles): a tile whose next level would pass this
  // is split and redone, so the budget costs time, not refinement. Only a single triangle past it
  // has that level made final (still conservative: what is not proven covered is reported uncovered).
  std::size_t max_subtriangles = std::size_t{1} << 23;
};

// One final sub-triangle that is not proven covered.
struct UncoveredPiece {
  std::array<Eigen::Vector3d, 3> corners;              // m
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // m, its centroid (a point of the surface)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // unit face normal of its triangle
  std::uint32_t triangle = 0;
  double depth = 0.0;    // m, distance from `position` to the nearest centre (at least; see the doc)
  double bound = 0.0;    // m, no point of the piece is farther than this from the nearest centre
  double edge = 0.0;     // m, its longest edge
  double area = 0.0;     // m^2
  bool searched = true;  // false: the GPU search hit max_shells first; bounded on the CPU instead
};

struct CoverageCertificate {
  double radius = 0.0;          // m, the ball radius tested
  bool covered = false;         // proven: every surface point lies within `radius` of a centre
  double covering_bound = 0.0;  // m, c <= this (certified, float margin included)
  double covering_lower = 0.0;  // m, c >= this (the deepest point the certificate evaluated)
  std::size_t uncovered = 0;    // final sub-triangles not proven covered (0 exactly when `covered`)
  double uncovered_area = 0.0;  // m^2, their area: at least the area no ball covers
  std::size_t evaluated = 0;    // sub-triangles evaluated, all levels
  int levels = 0;
  double floor = 0.0;                  // m, radius / floor_divisor
  double margin = 0.0;                 // m, the float margin added to the bound (absolute part)
  bool budget_reached =
      false;              // one triangle's level was made final by CertificateSettings::max_subtriangles
  std::size_t tiles = 0;  // triangle ranges certified (1 when the whole mesh fitted the budget)
  std::size_t tiles_redone = 0;        // ranges given up past the budget and split
  std::vector<UncoveredPiece> pieces;  // every uncovered final sub-triangle, deepest first
};

// Up to `count` holes, deepest first, one point each: uncovered pieces taken in order of depth when
// at least separation * depth from every piece taken before, then each moved to the deepest of a
// grid of 45 points over it (its depth there exact, from `centres`, the certified ones): where the
// sampler puts particles, and what it reports.
std::vector<UncoveredPiece> deepest_holes(const CoverageCertificate& certificate,
                                          std::span<const Eigen::Vector3f> centres, std::size_t count,
                                          double separation = 1.0);

class GpuCoverageCertifier {
 public:
  // Uploads the mesh's triangles once, relative to the centre of its bounding box. `mesh` must
  // outlive the certifier.
  GpuCoverageCertifier(gpu::Context& context, const TriangleMesh& mesh, bool timings = false);
  GpuCoverageCertifier(const GpuCoverageCertifier&) = delete;
  GpuCoverageCertifier& operator=(const GpuCoverageCertifier&) = delete;

  // Certifies balls of `radius` [m] > 0 about `centres` (m, mesh coordinates, at least one): the
  // particles as a body stores them. Same input, same device: same result, bit for bit.
  CoverageCertificate certify(std::span<const Eigen::Vector3f> centres, double radius,
                              const CertificateSettings& settings = {});

  std::string timing_report() { return queue_.timing_report(); }

 private:
  struct Frame;
  struct LevelCounts {
    std::uint32_t children = 0, uncovered = 0;
  };
  // What certifying one range of triangles gave; `over_budget`: given up, the range must be split.
  struct Tile {
    std::vector<UncoveredPiece> pieces;
    std::size_t evaluated = 0;
    int levels = 0;
    bool budget_reached = false;
    bool over_budget = false;
    std::uint32_t children = 0;  // with over_budget: the sub-triangles the level would have made
  };
  Frame upload_centres(std::span<const Eigen::Vector3f> centres, double radius);
  void seed_queue(std::uint32_t begin, std::uint32_t end);
  Tile certify_tile(std::uint32_t begin, std::uint32_t end, const Frame& frame,
                    const CertificateSettings& settings, float& witness);
  LevelCounts evaluate(std::uint32_t count, const Frame& frame, const CertificateSettings& settings,
                       float witness_so_far, bool no_split);
  void scatter(std::uint32_t count, const LevelCounts& counts);
  std::vector<UncoveredPiece> read_pieces(std::uint32_t uncovered) const;
  void bound_unsearched(std::vector<UncoveredPiece>& pieces, std::span<const Eigen::Vector3f> centres,
                        double radius) const;
  void finish(CoverageCertificate& result, const Frame& frame, float witness) const;
  Eigen::Vector3d piece_point(std::uint32_t triangle, int level, std::uint32_t a, std::uint32_t b) const;
  UncoveredPiece make_piece(const Eigen::Vector4i& id, const Eigen::Vector3f& bounds) const;

  const TriangleMesh& mesh_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // m, the local origin (float-representable)
  double mesh_extent_ = 0.0;  // m, largest |coordinate| of a vertex relative to the origin
  gpu::ShaderLibrary library_;
  gpu::Queue queue_;
  gpu::Program evaluate_, scatter_;
  gpu::ParamBlock<gpu::params::CertifyParams> evaluate_params_;
  gpu::ParamBlock<gpu::params::ItemCount> scatter_params_;
  gpu::HashGrid grid_;
  gpu::PrefixScan scan_;
  gpu::Buffer triangles_, centres_, queue_buffers_[2], splits_, uncovered_, bounds_, totals_, holes_;
};

}  // namespace ts::sampler
