#include "sampler/cpu_coverage_certificate.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/error.h"
#include "core/log.h"

namespace ts::sampler {
namespace {

// Double-precision margin (docs/coverage-certificate.md, "The CPU certifier"): the GPU's argument
// with the unit roundoff of double, 2^-53. Positions and distances are within about 20 u M + 8 u d of
// their exact values (M the largest local coordinate, d the distance); the margin is 64 units of each.
constexpr double kUnitRoundoff = 0x1p-53;
constexpr double kMarginUlps = 64.0;
constexpr double kRelative = kMarginUlps * kUnitRoundoff;
// The GPU stops at level 24 (i, j and 2^-level exact in float); the CPU keeps the same last level.
constexpr int kMaxLevel = 24;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Cell coordinates are kept well inside int so that shell arithmetic never overflows.
constexpr double kMaxCell = 1 << 29;

using Corners = std::array<Eigen::Vector3d, 3>;

// One set of centres and a radius, and the margins that make double arithmetic a proof.
struct Frame {
  double radius = 0.0;       // m, tested
  double extent = 0.0;       // m, largest distance of a vertex or centre from the local origin
  double margin = 0.0;       // m, absolute part of the margin
  double test_radius = 0.0;  // m, what U is compared with: the radius less the margin

  double upper(double bound) const { return bound * (1.0 + kRelative) + margin; }
  double lower(double distance) const { return std::max(distance * (1.0 - kRelative) - margin, 0.0); }
};

// A sub-triangle: the "up" piece (i, j) of level k has the parameter corners (i, j), (i+1, j), (i, j+1),
// the "down" piece (i+1, j), (i, j+1), (i+1, j+1), in steps of 2^-k (the GPU's ids).
struct PieceId {
  std::uint32_t triangle = 0;
  int level = 0;
  bool down = false;
  std::uint32_t i = 0, j = 0;
};

// The midpoint split on the level + 1 grid, in the order of shaders/sampler/certify_scatter.comp: an
// up (i, j) holds the ups (2i, 2j), (2i+1, 2j), (2i, 2j+1) and the down (2i, 2j); a down (i, j) the
// downs (2i+1, 2j), (2i, 2j+1), (2i+1, 2j+1) and the up (2i+1, 2j+1).
std::array<PieceId, 4> children(const PieceId& p) {
  const int k = p.level + 1;
  const std::uint32_t i = 2 * p.i, j = 2 * p.j, t = p.triangle;
  if (!p.down)
    return {{{t, k, false, i, j}, {t, k, false, i + 1, j}, {t, k, false, i, j + 1}, {t, k, true, i, j}}};
  return {{{t, k, true, i + 1, j},
           {t, k, true, i, j + 1},
           {t, k, true, i + 1, j + 1},
           {t, k, false, i + 1, j + 1}}};
}

// The parameter corners (a, b) of a piece, in steps of 2^-level.
std::array<std::array<std::uint32_t, 2>, 3> grid_corners(const PieceId& p) {
  if (p.down) return {{{p.i + 1, p.j}, {p.i, p.j + 1}, {p.i + 1, p.j + 1}}};
  return {{{p.i, p.j}, {p.i + 1, p.j}, {p.i, p.j + 1}}};
}

// An evaluated piece (bounds as computed, before the margin).
struct Leaf {
  PieceId id;
  double bound = 0.0;    // m, U
  double nearest = 0.0;  // m, n: centroid to its nearest centre
  double edge = 0.0;     // m, its longest edge
  bool covered = false;
  bool wholly_uncovered = false;  // n - rho > the test radius: no point of it is covered
};

// One triangle's refinement. After the first pass, `leaves` holds its final pieces that later
// rounds may split (every uncovered one, and the covered ones the bound rule may reach); during the
// rounds, the pieces still to judge. The other final pieces are summed up in `bound`, or, uncovered
// after the rounds, in `holes`.
struct TriangleOutcome {
  std::vector<Leaf> leaves;
  std::vector<Leaf> holes;
  double bound = 0.0;    // m, largest U of the final pieces in neither list
  double witness = 0.0;  // m, largest n of an evaluated piece
  std::size_t evaluated = 0;
  int levels = 0;
};

// The fate of a piece, as on the GPU (certify_evaluate.comp, a search that completed).
struct Rules {
  double test_radius = 0.0;  // m: covered when U is at most this
  double floor = 0.0;        // m: a piece with its longest edge at most this is final
  double resolution = 0.0;   // m: the same for an undecided piece (neither covered nor wholly uncovered)
  double split_above = kInfinity;  // m: a piece with U above this is split to sharpen the bound
  // First pass only: the largest witness any triangle has reported so far (a lower bound of the
  // pass's own), so that a covered final piece is kept as a leaf while the rounds' bound rule may
  // still split it. It decides what is kept, never what is split: the result does not depend on it.
  std::atomic<double>* witness_so_far = nullptr;
  double radius = 0.0;  // m, with floor_divisor: the bound rule's tolerance max(radius, L) / floor_divisor
  double floor_divisor = 64.0;
};

// Squared distances from one piece to the centres.
struct Distances {
  double bound2 = kInfinity;    // m^2: U^2, smallest largest-corner distance over the centres seen
  double nearest2 = kInfinity;  // m^2: n^2, smallest centroid distance (exact)
};

// The centres in hashed cells of side `cell` (a bucket shared by colliding cells only adds
// candidates), searched in cubic shells of cells around a piece's centroid.
class CentreGrid {
 public:
  // `slack` [m]: how far a rounded cell index may misplace a point (the frame's margin).
  CentreGrid(std::span<const Eigen::Vector3d> centres, double cell, double slack)
      : cell_(cell), slack_(slack) {
    const std::size_t buckets = std::bit_ceil(std::max<std::size_t>(2 * centres.size(), 64));
    mask_ = buckets - 1;
    cell_min_ = Eigen::Vector3i::Constant(std::numeric_limits<int>::max());
    cell_max_ = Eigen::Vector3i::Constant(std::numeric_limits<int>::min());
    std::vector<std::size_t> bucket(centres.size());
    bucket_start_.assign(buckets + 1, 0);
    for (std::size_t k = 0; k < centres.size(); ++k) {
      const Eigen::Vector3i c = cell_of(centres[k]);
      cell_min_ = cell_min_.cwiseMin(c);
      cell_max_ = cell_max_.cwiseMax(c);
      bucket[k] = bucket_of(c);
      ++bucket_start_[bucket[k] + 1];
    }
    for (std::size_t b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
    std::vector<std::size_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
    sorted_.resize(centres.size());
    for (std::size_t k = 0; k < centres.size(); ++k) sorted_[fill[bucket[k]]++] = centres[k];
  }

  // n exact; U exact, or, when it exceeds `decided_beyond` [m], possibly larger but still above it
  // (so every comparison of U with a threshold up to `decided_beyond` is exact), and always the
  // distance to a real centre, an upper bound. After shell r every centre within `clearance` of g has
  // been seen; an unseen one p has max over the corners |v - p| >= |g - p| > clearance (g is a convex
  // combination of the corners), so it can lower neither n nor U once both are within it.
  Distances search(const Corners& v, const Eigen::Vector3d& g, double decided_beyond) const {
    Distances d;
    const Eigen::Vector3i centre = cell_of(g);
    // Once the cube of visited cells spans the centres' cells, every centre was seen.
    const int last_ring = std::max({0, (centre - cell_min_).maxCoeff(), (cell_max_ - centre).maxCoeff()});
    // A centroid far from every centre would walk through shells of empty cells: once that costs
    // more than looking at every centre, do that instead.
    const std::size_t cell_budget = 4 * sorted_.size() + 64;
    std::size_t visited = 0;
    for (int r = 0;; ++r) {
      visited += visit_shell(centre, r, v, g, d);
      if (r >= last_ring) return d;
      if (visited > cell_budget) {
        visit_bucket_range(0, sorted_.size(), v, g, d);
        return d;
      }
      const double clear = clearance(g, centre, r);
      if (!(clear > 0.0)) continue;
      const double clear2 = clear * clear;
      if (d.nearest2 <= clear2 && (d.bound2 <= clear2 || clear > decided_beyond)) return d;
    }
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a)
      c[a] = static_cast<int>(std::clamp(std::floor(p[a] / cell_), -kMaxCell, kMaxCell));
    return c;
  }

  // Teschner et al. 2003, as sampler/point_grid.cpp.
  std::size_t bucket_of(const Eigen::Vector3i& c) const {
    const auto x = static_cast<std::uint64_t>(static_cast<std::int64_t>(c.x())) * 73856093u;
    const auto y = static_cast<std::uint64_t>(static_cast<std::int64_t>(c.y())) * 19349663u;
    const auto z = static_cast<std::uint64_t>(static_cast<std::int64_t>(c.z())) * 83492791u;
    return static_cast<std::size_t>((x ^ y ^ z) & mask_);
  }

  // Distance from g to the outside of the cube of cells within r of `centre`, less what rounding of
  // the cell bounds and of the centres' cell indices may hide.
  double clearance(const Eigen::Vector3d& g, const Eigen::Vector3i& centre, int r) const {
    const Eigen::Vector3d lo = (centre.array() - r).cast<double>().matrix() * cell_;
    const Eigen::Vector3d hi = (centre.array() + r + 1).cast<double>().matrix() * cell_;
    const double reach = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    return std::min((g - lo).minCoeff(), (hi - g).minCoeff()) - slack_ - kRelative * reach;
  }

  void visit_bucket_range(std::size_t begin, std::size_t end, const Corners& v, const Eigen::Vector3d& g,
                          Distances& d) const {
    for (std::size_t k = begin; k < end; ++k) {
      const Eigen::Vector3d& p = sorted_[k];
      const double centroid2 = (g - p).squaredNorm();
      d.nearest2 = std::min(d.nearest2, centroid2);
      // The farthest corner is at least as far as the centroid: such a centre cannot lower U.
      if (centroid2 >= d.bound2) continue;
      d.bound2 = std::min(
          d.bound2, std::max({(v[0] - p).squaredNorm(), (v[1] - p).squaredNorm(), (v[2] - p).squaredNorm()}));
    }
  }

  // The cells at Chebyshev distance r from `centre` (r = 0: itself); returns how many.
  std::size_t visit_shell(const Eigen::Vector3i& centre, int r, const Corners& v, const Eigen::Vector3d& g,
                          Distances& d) const {
    std::size_t visited = 0;
    for (int dz = -r; dz <= r; ++dz)
      for (int dy = -r; dy <= r; ++dy) {
        // Rows inside the shell's faces hold only its two end cells.
        const int step = (std::abs(dz) == r || std::abs(dy) == r) ? 1 : 2 * r;
        for (int dx = -r; dx <= r; dx += step) {
          const std::size_t b = bucket_of(centre + Eigen::Vector3i(dx, dy, dz));
          visit_bucket_range(bucket_start_[b], bucket_start_[b + 1], v, g, d);
          ++visited;
        }
      }
    return visited;
  }

  double cell_, slack_;
  std::size_t mask_ = 0;                   // bucket count - 1 (a power of two)
  std::vector<std::size_t> bucket_start_;  // bucket b holds sorted_[start[b], start[b+1])
  std::vector<Eigen::Vector3d> sorted_;    // m, local frame, in bucket order
  Eigen::Vector3i cell_min_, cell_max_;    // cells of the centres' bounding box
};

}  // namespace

// Evaluates and refines pieces under one set of rules; thread-safe (each call owns its outcome).
class CpuCoverageCertifier::Pass {
 public:
  Pass(const std::vector<LocalTriangle>& triangles, const CentreGrid& grid, const Rules& rules)
      : triangles_(triangles), grid_(grid), rules_(rules) {
    // U is compared with the test radius and split_above: the search must decide both exactly.
    decided_beyond_ =
        std::isfinite(rules.split_above) ? std::max(rules.test_radius, rules.split_above) : rules.test_radius;
  }

  // A whole triangle, depth first from its level-0 piece.
  TriangleOutcome refine_triangle(std::uint32_t triangle) const {
    TriangleOutcome out;
    refine(PieceId{triangle, 0, false, 0, 0}, out);
    if (rules_.witness_so_far) raise(*rules_.witness_so_far, out.witness);
    return out;
  }

  // One round: each leaf these rules split is replaced by its four children, evaluated (the next
  // round judges them); the others are final.
  void split_once(TriangleOutcome& t) const {
    std::vector<Leaf> next;
    for (const Leaf& leaf : t.leaves) {
      if (splits(leaf)) {
        for (const PieceId& child : children(leaf.id)) next.push_back(evaluate(child, t));
      } else if (leaf.covered) {
        t.bound = std::max(t.bound, leaf.bound);
      } else {
        t.holes.push_back(leaf);
      }
    }
    t.leaves = std::move(next);
  }

 private:
  // U and n of a piece from the grid.
  Leaf evaluate(const PieceId& piece, TriangleOutcome& out) const {
    const LocalTriangle& t = triangles_[piece.triangle];
    const Corners v = corners(t, piece);
    const Eigen::Vector3d g = (v[0] + v[1] + v[2]) / 3.0;
    const double rho =
        std::sqrt(std::max({(v[0] - g).squaredNorm(), (v[1] - g).squaredNorm(), (v[2] - g).squaredNorm()}));
    const Distances d = grid_.search(v, g, decided_beyond_);
    Leaf leaf;
    leaf.id = piece;
    leaf.bound = std::sqrt(d.bound2);
    leaf.nearest = std::sqrt(d.nearest2);
    leaf.edge = std::ldexp(t.longest, -piece.level);  // midpoint pieces halve every edge
    leaf.covered = leaf.bound <= rules_.test_radius;
    // Every point of the piece is farther than the radius from every centre.
    leaf.wholly_uncovered = leaf.nearest - rho > rules_.test_radius;
    ++out.evaluated;
    out.levels = std::max(out.levels, piece.level + 1);
    out.witness = std::max(out.witness, leaf.nearest);
    return leaf;
  }

  // The GPU's rule (docs/coverage-certificate.md, "The subdivision"): split above the floor when
  // undecided, or when U is above the bound rule's threshold.
  bool splits(const Leaf& leaf) const {
    const bool at_floor = leaf.edge <= rules_.floor || leaf.id.level >= kMaxLevel;
    const bool undecided = !leaf.covered && !leaf.wholly_uncovered && leaf.edge > rules_.resolution;
    return !at_floor && (leaf.bound > rules_.split_above || undecided);
  }

  void refine(const PieceId& piece, TriangleOutcome& out) const {
    const Leaf leaf = evaluate(piece, out);
    if (splits(leaf)) {
      for (const PieceId& child : children(piece)) refine(child, out);
    } else if (!leaf.covered || may_split_later(leaf.bound, out.witness)) {
      out.leaves.push_back(leaf);
    } else {
      out.bound = std::max(out.bound, leaf.bound);
    }
  }

  // First pass: whether a later round's bound rule may split a covered final piece with this U. Its
  // threshold is L + max(radius, L) / floor_divisor for a witness L at least the one known now, and
  // the threshold grows with L: a piece at or below it now never is split.
  bool may_split_later(double bound, double local_witness) const {
    if (!rules_.witness_so_far) return false;
    const double known = std::max(local_witness, rules_.witness_so_far->load(std::memory_order_relaxed));
    return bound > known + std::max(rules_.radius, known) / rules_.floor_divisor;
  }

  static void raise(std::atomic<double>& value, double at_least) {
    double now = value.load(std::memory_order_relaxed);
    while (now < at_least && !value.compare_exchange_weak(now, at_least, std::memory_order_relaxed)) {
    }
  }

  // corner + (edge1 a + edge2 b) 2^-level, in the GPU's order of operations.
  static Corners corners(const LocalTriangle& t, const PieceId& p) {
    Corners v;
    const auto ab = grid_corners(p);
    for (int k = 0; k < 3; ++k) {
      v[k] = t.corner + (t.edge1 * std::ldexp(double(ab[k][0]), -p.level) +
                         t.edge2 * std::ldexp(double(ab[k][1]), -p.level));
    }
    return v;
  }

  const std::vector<LocalTriangle>& triangles_;
  const CentreGrid& grid_;
  Rules rules_;
  double decided_beyond_ = 0.0;
};

CpuCoverageCertifier::CpuCoverageCertifier(const TriangleMesh& mesh) : mesh_(mesh) {
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
    if (!mesh.vertices[k].allFinite())
      throw InputError(fmt::format("coverage certificate: mesh vertex {} is not finite", k));
  }
  if (!mesh.vertices.empty()) origin_ = bounding_box(mesh).center();
  triangles_.reserve(mesh.triangle_count());
  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[tri[0]] - origin_, b = mesh.vertices[tri[1]] - origin_,
                          c = mesh.vertices[tri[2]] - origin_;
    triangles_.push_back({a, b - a, c - a, std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()})});
    mesh_extent_ = std::max({mesh_extent_, a.norm(), b.norm(), c.norm()});
  }
}

namespace {

// A final uncovered piece in mesh coordinates (double, from the mesh's own vertices, as the GPU
// certifier reports them), its bounds widened by the frame's margin.
UncoveredPiece make_piece(const TriangleMesh& mesh, const Leaf& hole, const Frame& frame) {
  const auto& tri = mesh.triangles[hole.id.triangle];
  const Eigen::Vector3d& v0 = mesh.vertices[tri[0]];
  const double step = std::ldexp(1.0, -hole.id.level);
  const auto ab = grid_corners(hole.id);
  UncoveredPiece p;
  for (int k = 0; k < 3; ++k) {
    p.corners[k] = v0 + (mesh.vertices[tri[1]] - v0) * (ab[k][0] * step) +
                   (mesh.vertices[tri[2]] - v0) * (ab[k][1] * step);
  }
  const auto& [a, b, c] = p.corners;
  p.triangle = hole.id.triangle;
  p.position = (a + b + c) / 3.0;
  const Eigen::Vector3d cross = (b - a).cross(c - a);
  p.area = 0.5 * cross.norm();
  if (p.area > 0.0)
    p.normal = (hole.id.down ? -cross : cross).normalized();  // a down piece turns the other way
  p.edge = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  p.bound = frame.upper(hole.bound);
  p.depth = frame.lower(hole.nearest);
  p.searched = true;
  return p;
}

// Every triangle's outcome into its own slot, in parallel (so the result does not depend on the
// thread count or the schedule).
template <class Step>
std::vector<TriangleOutcome> for_each_triangle(std::size_t count, const Step& step) {
  std::vector<TriangleOutcome> outcomes(count);
  tbb::parallel_for(std::size_t{0}, count,
                    [&](std::size_t t) { outcomes[t] = step(static_cast<std::uint32_t>(t)); });
  return outcomes;
}

std::size_t leaf_count(const std::vector<TriangleOutcome>& outcomes) {
  std::size_t leaves = 0;
  for (const TriangleOutcome& o : outcomes) leaves += o.leaves.size();
  return leaves;
}

double largest_witness(const std::vector<TriangleOutcome>& outcomes) {
  double witness = 0.0;
  for (const TriangleOutcome& o : outcomes) witness = std::max(witness, o.witness);
  return witness;
}

std::size_t total_evaluated(const std::vector<TriangleOutcome>& outcomes) {
  std::size_t evaluated = 0;
  for (const TriangleOutcome& o : outcomes) evaluated += o.evaluated;
  return evaluated;
}

}  // namespace

CoverageCertificate CpuCoverageCertifier::certify(std::span<const Eigen::Vector3f> centres, double radius,
                                                  const CertificateSettings& settings) {
  if (centres.empty()) throw Error(ExitCode::Internal, "coverage certificate: no centres");
  if (!(radius > 0.0) || !std::isfinite(radius) || !(settings.floor_divisor >= 1.0) ||
      !(settings.hole_divisor >= 1.0)) {
    throw Error(ExitCode::Internal, "coverage certificate: radius or divisors out of range");
  }
  // The local frame and its margin.
  Frame frame;
  frame.radius = radius;
  frame.extent = mesh_extent_;
  std::vector<Eigen::Vector3d> local(centres.size());
  for (std::size_t k = 0; k < centres.size(); ++k) {
    if (!centres[k].allFinite())
      throw InputError(fmt::format("coverage certificate: centre {} is not finite", k));
    local[k] = centres[k].cast<double>() - origin_;
    frame.extent = std::max(frame.extent, local[k].norm());
  }
  frame.margin = kMarginUlps * kUnitRoundoff * frame.extent;
  frame.test_radius = (radius - frame.margin) / (1.0 + kRelative);
  if (!(frame.test_radius > 0.0)) {
    throw InputError(
        fmt::format("coverage certificate: radius {:.4g} m is below the double-precision margin {:.4g} m of "
                    "a mesh {:.4g} m "
                    "across",
                    radius, frame.margin, 2.0 * frame.extent));
  }
  const CentreGrid grid(local, radius, frame.margin);
  const double floor = radius / settings.floor_divisor;
  const double hole_resolution = std::max(floor, radius / settings.hole_divisor);

  // Pass 1, depth first: split only what is undecided, down to the hole resolution. It gives the
  // verdict where a hole is proven, and a first witness.
  std::atomic<double> witness_so_far{0.0};
  const Pass pass1(triangles_, grid,
                   {frame.test_radius, floor, hole_resolution, kInfinity, &witness_so_far, radius,
                    settings.floor_divisor});
  std::vector<TriangleOutcome> outcomes =
      for_each_triangle(triangles_.size(), [&](std::uint32_t t) { return pass1.refine_triangle(t); });
  log::debug("cpu certificate: pass 1 evaluated {} pieces, kept {} leaves", total_evaluated(outcomes),
             leaf_count(outcomes));

  // Then rounds over the leaves, one level each, as the GPU's levels: the bound rule with the
  // threshold L + max(R, L) / floor_divisor for the witness L of the rounds before, and, while no
  // witness exceeds R (the verdict is open), undecided pieces down to the floor. L is fixed within a
  // round, so the result is the same on every schedule; it only grows, so every final piece is at or
  // below the final threshold, or at the floor (docs/coverage-certificate.md, "The CPU certifier").
  for (int round = 0; leaf_count(outcomes) > 0; ++round) {
    const double witness = largest_witness(outcomes);
    const double split_above = witness + std::max(radius, witness) / settings.floor_divisor;
    const Pass pass(
        triangles_, grid,
        {frame.test_radius, floor, witness > frame.test_radius ? hole_resolution : floor, split_above});
    tbb::parallel_for(std::size_t{0}, outcomes.size(), [&](std::size_t t) { pass.split_once(outcomes[t]); });
    log::debug("cpu certificate: round {} (witness {:.6g} m, split above {:.6g} m): {} leaves to judge",
               round, witness, split_above, leaf_count(outcomes));
  }

  CoverageCertificate result;
  result.radius = radius;
  result.floor = floor;
  result.margin = frame.margin;
  result.tiles = 1;
  double bound = 0.0;
  for (const TriangleOutcome& o : outcomes) {
    bound = std::max(bound, o.bound);
    result.evaluated += o.evaluated;
    result.levels = std::max(result.levels, o.levels);
    for (const Leaf& leaf : o.holes) {
      bound = std::max(bound, leaf.bound);
      result.pieces.push_back(make_piece(mesh_, leaf, frame));
    }
  }
  for (const UncoveredPiece& p : result.pieces) result.uncovered_area += p.area;
  std::stable_sort(result.pieces.begin(), result.pieces.end(),
                   [](const UncoveredPiece& a, const UncoveredPiece& b) { return a.depth > b.depth; });
  result.uncovered = result.pieces.size();
  result.covered = result.pieces.empty();
  result.covering_bound = frame.upper(bound);
  result.covering_lower = frame.lower(largest_witness(outcomes));
  return result;
}

}  // namespace ts::sampler
