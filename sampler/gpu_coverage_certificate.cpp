#include "sampler/gpu_coverage_certificate.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/log.h"
#include "gpu/layouts.h"
#include "sampler/point_grid.h"
#include "shaders/common/bindings.h"
#include "shaders/sampler/bindings.h"

namespace ts::sampler {
namespace {

using gpu::layout::CertLeaf;
using gpu::layout::CertTriangle;

// Float margin (docs/coverage-certificate.md, "Float precision"): every GPU position and distance is
// within kMarginUlps units in the last place (2^-24) of the largest local coordinate, plus as many of
// the distance itself, of the exact value. The estimate of the rounding is about a fifth of that.
constexpr double kUnitRoundoff = 0x1p-24;
constexpr double kMarginUlps = 64.0;

// Grows `buffer` to at least `bytes` (by powers of two, so a run of levels reallocates rarely).
void ensure(gpu::Buffer& buffer, std::size_t bytes) {
  bytes = std::max<std::size_t>(bytes, 16);
  if (buffer.bytes() < bytes) buffer = gpu::Buffer(std::bit_ceil(bytes));
}

float bits_to_float(std::uint32_t bits) { return std::bit_cast<float>(bits); }

// A level of n sub-triangles has at most 4n children, totalled by a 32-bit scan over n + 1 flags:
// 4n + 1 must fit in a uint, the only bound on a level's size (dispatches of any size go out as a 2D
// grid of work groups, gpu::Queue::dispatch_items).
constexpr std::size_t kMaxLevelItems = (std::size_t{std::numeric_limits<std::uint32_t>::max()} - 1) / 4;

}  // namespace

// The certificate's local frame for one set of centres, and its float margins.
struct GpuCoverageCertifier::Frame {
  double radius = 0.0;       // m, tested
  double extent = 0.0;       // m, largest distance of a vertex or centre from the origin
  double margin = 0.0;       // m, absolute part of the float margin
  double relative = 0.0;     // relative part of the float margin
  double test_radius = 0.0;  // m, what the GPU compares U with: radius less the margin
  std::uint32_t centres = 0;

  double upper(double gpu_bound) const { return gpu_bound * (1.0 + relative) + margin; }
  double lower(double gpu_distance) const { return std::max(gpu_distance * (1.0 - relative) - margin, 0.0); }
};

// The deepest of the points (i, j) / 8 of a piece's parameter triangle, with its exact depth.
void move_to_deepest_point(UncoveredPiece& piece, const PointGrid& grid) {
  constexpr int kSteps = 8;
  const auto& [a, b, c] = piece.corners;
  for (int i = 0; i <= kSteps; ++i)
    for (int j = 0; i + j <= kSteps; ++j) {
      const Eigen::Vector3d x = a + (b - a) * (double(i) / kSteps) + (c - a) * (double(j) / kSteps);
      const double depth = grid.nearest(x).distance;
      if (depth > piece.depth) {
        piece.position = x;
        piece.depth = depth;
      }
    }
}

std::vector<UncoveredPiece> deepest_holes(const CoverageCertificate& certificate,
                                          std::span<const Eigen::Vector3f> centres, std::size_t count,
                                          double separation) {
  std::vector<UncoveredPiece> picked;
  if (count == 0 || certificate.pieces.empty() || centres.empty()) return picked;
  SeparatedPicks picks(separation * certificate.pieces.front().depth);
  for (const UncoveredPiece& piece : certificate.pieces) {  // deepest first
    if (picked.size() == count) break;
    if (picks.try_add(piece.position, separation * piece.depth)) picked.push_back(piece);
  }
  std::vector<Eigen::Vector3d> points(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) points[i] = centres[i].cast<double>();
  const PointGrid grid(points, certificate.radius);
  for (UncoveredPiece& piece : picked) {
    piece.depth = grid.nearest(piece.position).distance;
    move_to_deepest_point(piece, grid);
  }
  std::stable_sort(picked.begin(), picked.end(),
                   [](const UncoveredPiece& a, const UncoveredPiece& b) { return a.depth > b.depth; });
  return picked;
}

GpuCoverageCertifier::GpuCoverageCertifier(gpu::Context& context, const TriangleMesh& mesh, bool timings)
    : mesh_(mesh),
      queue_(timings, context.debug()),
      evaluate_(gpu::Program::compute(library_, "sampler/certify_evaluate.comp")),
      scatter_(gpu::Program::compute(library_, "sampler/certify_scatter.comp")),
      grid_(library_),
      scan_(library_) {
  const Aabb box = bounding_box(mesh);
  if (!mesh.vertices.empty()) origin_ = (0.5 * (box.min + box.max)).cast<float>().cast<double>();
  std::vector<CertTriangle> triangles;
  triangles.reserve(mesh.triangle_count());
  auto vec4 = [](const Eigen::Vector3d& v, double w) {
    return gpu::layout::vec4{static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()),
                             static_cast<float>(w)};
  };
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    triangles.push_back({vec4(a - origin_, 0.0), vec4(b - a, longest), vec4(c - a, 0.0)});
    for (const auto* v : {&a, &b, &c}) mesh_extent_ = std::max(mesh_extent_, (*v - origin_).norm());
  }
  triangles_ = gpu::Buffer(std::max<std::size_t>(triangles.size(), 1) * sizeof(CertTriangle));
  if (!triangles.empty()) triangles_.upload(std::span<const CertTriangle>(triangles));
  totals_ = gpu::Buffer(sizeof(gpu::layout::uvec4));
}

GpuCoverageCertifier::Frame GpuCoverageCertifier::upload_centres(std::span<const Eigen::Vector3f> centres,
                                                           double radius) {
  Frame frame;
  frame.radius = radius;
  frame.extent = mesh_extent_;
  frame.centres = static_cast<std::uint32_t>(centres.size());
  std::vector<gpu::layout::vec4> local(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3d p = centres[i].cast<double>() - origin_;
    frame.extent = std::max(frame.extent, p.norm());
    local[i] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), 0.0f};
  }
  frame.relative = kMarginUlps * kUnitRoundoff;
  frame.margin = kMarginUlps * kUnitRoundoff * frame.extent;
  frame.test_radius = (radius - frame.margin) / (1.0 + frame.relative);
  if (!(frame.test_radius > 0.0)) {
    throw InputError(
        fmt::format("coverage certificate: radius {:.4g} m is below the float margin {:.4g} m of a "
                    "mesh {:.4g} m across",
                    radius, frame.margin, 2.0 * frame.extent));
  }
  ensure(centres_, local.size() * sizeof(gpu::layout::vec4));
  centres_.upload(std::span<const gpu::layout::vec4>(local));
  grid_.build(queue_, centres_, frame.centres, static_cast<float>(radius));
  return frame;
}

void GpuCoverageCertifier::seed_queue(std::uint32_t begin, std::uint32_t end) {
  std::vector<gpu::layout::uvec4> level0(end - begin);
  for (std::uint32_t t = begin; t < end; ++t) level0[t - begin] = {t, 0u, 0u, 0u};
  ensure(queue_buffers_[0], level0.size() * sizeof(gpu::layout::uvec4));
  if (!level0.empty()) queue_buffers_[0].upload(std::span<const gpu::layout::uvec4>(level0));
}

GpuCoverageCertifier::LevelCounts GpuCoverageCertifier::evaluate(std::uint32_t count, const Frame& frame,
                                                           const CertificateSettings& settings,
                                                           float witness_so_far, bool no_split) {
  ensure(splits_, (count + 1) * sizeof(std::uint32_t));
  ensure(uncovered_, (count + 1) * sizeof(std::uint32_t));
  ensure(bounds_, count * sizeof(gpu::layout::vec4));
  centres_.bind(TS_CERT_CENTRES);
  triangles_.bind(TS_CERT_TRIANGLES);
  queue_buffers_[0].bind(TS_CERT_QUEUE);
  grid_.bind();
  splits_.bind(TS_CERT_SPLITS);
  uncovered_.bind(TS_CERT_UNCOVERED);
  bounds_.bind(TS_CERT_BOUNDS);
  totals_.bind(TS_CERT_TOTALS);
  const double floor = frame.radius / settings.floor_divisor;
  gpu::params::CertifyParams& p = evaluate_params_.values;
  p.sizes = {count, grid_.table_size(), no_split ? 1u : 0u, 0u};
  p.search = {settings.max_shells, 0, 0, 0};
  p.lengths = {grid_.cell_size(), static_cast<float>(frame.margin), static_cast<float>(frame.test_radius),
               static_cast<float>(floor)};
  // The bound is refined to within the floor of the covering radius found so far, or the same
  // fraction of it in a hole deeper than the radius.
  p.refine = {static_cast<float>(std::max(floor, frame.radius / settings.hole_divisor)),
              static_cast<float>(std::max(frame.radius, double{witness_so_far}) / settings.floor_divisor),
              witness_so_far, 0.0f};
  evaluate_params_.bind(TS_SAMPLER_PARAMS);
  queue_.dispatch_items(evaluate_, std::size_t{count} + 1);
  scan_.run(queue_, splits_, count + 1);
  scan_.run(queue_, uncovered_, count + 1);
  LevelCounts counts;
  counts.children = splits_.read<std::uint32_t>(1, count).front();
  counts.uncovered = uncovered_.read<std::uint32_t>(1, count).front();
  return counts;
}

void GpuCoverageCertifier::scatter(std::uint32_t count, const LevelCounts& counts) {
  ensure(queue_buffers_[1], counts.children * sizeof(gpu::layout::uvec4));
  ensure(holes_, counts.uncovered * sizeof(CertLeaf));
  queue_buffers_[0].bind(TS_CERT_QUEUE);
  splits_.bind(TS_CERT_SPLITS);
  uncovered_.bind(TS_CERT_UNCOVERED);
  bounds_.bind(TS_CERT_BOUNDS);
  queue_buffers_[1].bind(TS_CERT_NEXT_QUEUE);
  holes_.bind(TS_CERT_HOLES);
  scatter_params_.values.count.x = count;
  scatter_params_.bind(TS_SAMPLER_PARAMS);
  queue_.dispatch_items(scatter_, count);
  std::swap(queue_buffers_[0], queue_buffers_[1]);
}

Eigen::Vector3d GpuCoverageCertifier::piece_point(std::uint32_t triangle, int level, std::uint32_t a,
                                               std::uint32_t b) const {
  const auto& t = mesh_.triangles[triangle];
  const Eigen::Vector3d& v0 = mesh_.vertices[t[0]];
  const double step = std::ldexp(1.0, -level);
  return v0 + (mesh_.vertices[t[1]] - v0) * (a * step) + (mesh_.vertices[t[2]] - v0) * (b * step);
}

// An uncovered sub-triangle in double precision, from its id and its GPU bounds (U and the witness,
// not yet widened by the float margin: finish() does that).
UncoveredPiece GpuCoverageCertifier::make_piece(const Eigen::Vector4i& id, const Eigen::Vector3f& bounds) const {
  const auto triangle = static_cast<std::uint32_t>(id.x());
  const int level = id.y() & 0xff;
  const bool down = (id.y() >> 8) != 0;
  const auto i = static_cast<std::uint32_t>(id.z()), j = static_cast<std::uint32_t>(id.w());
  const Eigen::Vector3d v0 =
      down ? piece_point(triangle, level, i + 1, j) : piece_point(triangle, level, i, j);
  const Eigen::Vector3d v1 =
      down ? piece_point(triangle, level, i, j + 1) : piece_point(triangle, level, i + 1, j);
  const Eigen::Vector3d v2 = piece_point(triangle, level, down ? i + 1 : i, j + 1);
  UncoveredPiece p;
  p.triangle = triangle;
  p.corners = {v0, v1, v2};
  p.position = (v0 + v1 + v2) / 3.0;
  const Eigen::Vector3d cross = (v1 - v0).cross(v2 - v0);
  p.area = 0.5 * cross.norm();
  if (p.area > 0.0)
    p.normal = (down ? -cross : cross).normalized();  // a down piece's corners turn the other way
  p.edge = std::max({(v1 - v0).norm(), (v2 - v1).norm(), (v0 - v2).norm()});
  p.bound = bounds.x();
  p.depth = bounds.y();
  p.searched = bounds.z() != 0.0f;
  return p;
}

std::vector<UncoveredPiece> GpuCoverageCertifier::read_pieces(std::uint32_t uncovered) const {
  const std::vector<CertLeaf> leaves = holes_.read<CertLeaf>(uncovered);
  std::vector<UncoveredPiece> pieces;
  pieces.reserve(leaves.size());
  for (const CertLeaf& leaf : leaves) {
    const Eigen::Vector4i id(static_cast<int>(leaf.id.x), static_cast<int>(leaf.id.y),
                             static_cast<int>(leaf.id.z), static_cast<int>(leaf.id.w));
    pieces.push_back(make_piece(id, Eigen::Vector3f(leaf.bounds.x, leaf.bounds.y, leaf.bounds.z)));
  }
  return pieces;
}

// Pieces whose GPU search stopped at its limit (a hole deeper than max_shells cells; U may be
// infinite): their depth is the exact distance from the centroid to the nearest centre (CPU, double),
// their bound the smaller of the GPU's and that distance plus the longest edge (every corner lies
// within an edge of the centroid).
void GpuCoverageCertifier::bound_unsearched(std::vector<UncoveredPiece>& pieces,
                                         std::span<const Eigen::Vector3f> centres, double radius) const {
  const auto unsearched = [](const UncoveredPiece& p) { return !p.searched; };
  if (std::none_of(pieces.begin(), pieces.end(), unsearched)) return;
  std::vector<Eigen::Vector3d> points(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) points[i] = centres[i].cast<double>();
  const PointGrid grid(points, radius);
  for (UncoveredPiece& p : pieces) {
    if (p.searched) continue;
    const NearestPoint nearest = grid.nearest(p.position);
    p.depth = nearest.distance;
    p.bound = std::min(p.bound, nearest.distance + p.edge);
  }
}

void GpuCoverageCertifier::finish(CoverageCertificate& result, const Frame& frame, float witness) const {
  const auto totals = totals_.read<std::uint32_t>(4);
  double bound = frame.upper(bits_to_float(totals[0]));
  for (UncoveredPiece& p : result.pieces) {
    p.bound = frame.upper(p.bound);
    p.depth = frame.lower(p.depth);
    bound = std::max(bound, p.bound);
    result.uncovered_area += p.area;
  }
  std::stable_sort(result.pieces.begin(), result.pieces.end(),
                   [](const UncoveredPiece& a, const UncoveredPiece& b) { return a.depth > b.depth; });
  result.uncovered = result.pieces.size();
  result.covered = result.pieces.empty();
  result.covering_bound = bound;
  result.covering_lower = frame.lower(witness);
  for (const UncoveredPiece& p : result.pieces)
    result.covering_lower = std::max(result.covering_lower, p.depth);
  result.margin = frame.margin;
}

GpuCoverageCertifier::Tile GpuCoverageCertifier::certify_tile(std::uint32_t begin, std::uint32_t end,
                                                        const Frame& frame,
                                                        const CertificateSettings& settings, float& witness) {
  Tile tile;
  seed_queue(begin, end);
  std::uint32_t count = end - begin;
  for (int level = 0; count > 0; ++level) {
    LevelCounts counts = evaluate(count, frame, settings, witness, false);
    if (counts.children > settings.max_subtriangles) {
      if (end - begin > 1) {
        tile.over_budget = true;
        tile.children = counts.children;
        return tile;
      }
      counts = evaluate(count, frame, settings, witness, true);
      tile.budget_reached = true;
    }
    scatter(count, counts);
    std::vector<UncoveredPiece> pieces = read_pieces(counts.uncovered);
    tile.pieces.insert(tile.pieces.end(), pieces.begin(), pieces.end());
    witness = bits_to_float(totals_.read<std::uint32_t>(2)[1]);
    log::debug("certificate level {}: {} sub-triangles, {} split, {} left uncovered, witness {:.4g} m", level,
               count, counts.children / 4, counts.uncovered, witness);
    tile.evaluated += count;
    tile.levels = level + 1;
    count = counts.children;
  }
  return tile;
}

CoverageCertificate GpuCoverageCertifier::certify(std::span<const Eigen::Vector3f> centres, double radius,
                                               const CertificateSettings& settings) {
  if (centres.empty()) throw Error(ExitCode::Internal, "coverage certificate: no centres");
  if (!(radius > 0.0) || !(settings.floor_divisor >= 1.0) || !(settings.hole_divisor >= 1.0) ||
      settings.max_shells < 1 || settings.max_subtriangles > kMaxLevelItems) {
    throw Error(ExitCode::Internal, "coverage certificate: radius, divisors, shells or budget out of range");
  }
  if (mesh_.triangle_count() > kMaxLevelItems) {
    throw InputError(fmt::format("coverage certificate: {} triangles, more than the {} it can take",
                                 mesh_.triangle_count(), kMaxLevelItems));
  }
  CoverageCertificate result;
  result.radius = radius;
  result.floor = radius / settings.floor_divisor;
  const Frame frame = upload_centres(centres, radius);
  totals_.fill_zero();
  float witness = 0.0f;
  // Ranges of triangles still to certify, the next one last. A range given up past the budget is
  // split into enough parts that each should fit; what its given-up levels added to the totals (the
  // largest bound of a final piece, the deepest point) are facts about real pieces of the surface,
  // so they stay: the bound can only be looser for it, never optimistic.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges{
      {0u, static_cast<std::uint32_t>(mesh_.triangle_count())}};
  while (!ranges.empty()) {
    const auto [begin, end] = ranges.back();
    ranges.pop_back();
    Tile tile = certify_tile(begin, end, frame, settings, witness);
    if (tile.over_budget) {
      const std::uint32_t size = end - begin;
      const std::uint32_t parts = std::clamp<std::uint32_t>(
          static_cast<std::uint32_t>(2 * (tile.children / settings.max_subtriangles + 1)), 2u, size);
      for (std::uint32_t k = parts; k-- > 0;) {
        ranges.emplace_back(begin + static_cast<std::uint32_t>(std::uint64_t{size} * k / parts),
                            begin + static_cast<std::uint32_t>(std::uint64_t{size} * (k + 1) / parts));
      }
      ++result.tiles_redone;
      log::debug(
          "certificate: triangles [{}, {}) would make {} sub-triangles at one level, over the budget of {}: "
          "split into {} tiles",
          begin, end, tile.children, settings.max_subtriangles, parts);
      continue;
    }
    result.pieces.insert(result.pieces.end(), tile.pieces.begin(), tile.pieces.end());
    result.evaluated += tile.evaluated;
    result.levels = std::max(result.levels, tile.levels);
    result.budget_reached = result.budget_reached || tile.budget_reached;
    ++result.tiles;
  }
  bound_unsearched(result.pieces, centres, radius);
  finish(result, frame, witness);
  return result;
}

}  // namespace ts::sampler
