#include "sdf/compute_scan.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/error.h"
#include "shaders/sdf/bindings.h"

namespace ts::sdf {
namespace {

struct PairEntry {
  std::uint32_t row, triangle, key;
};

// The float arithmetic of shaders/sdf/brick_pairs.comp, operation for operation (x86-64 SSE floats,
// no fused multiply-add: the build does not target FMA), so host and GPU make the same pairs.
struct Vec3f {
  float x, y, z;
  Vec3f operator-(const Vec3f& o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3f operator*(float s) const { return {x * s, y * s, z * s}; }
};
Vec3f xyz(const gpu::layout::vec4& v) { return {v.x, v.y, v.z}; }
float dot3(const Vec3f& a, const Vec3f& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
float edge_distance2(const Vec3f& from_start, const Vec3f& edge, float s) {
  const Vec3f r = from_start - edge * s;
  return dot3(r, r);
}

// Squared distance from p to triangle abc (brick_pairs.comp's triangle_distance2).
float triangle_distance2(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& n) {
  const Vec3f ab = b - a, ac = c - a, ap = p - a, bp = p - b, cp = p - c;
  const float d1 = dot3(ab, ap), d2 = dot3(ac, ap), d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  const float d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d1 <= 0.0f && d2 <= 0.0f) return dot3(ap, ap);
  if (d3 >= 0.0f && d4 <= d3) return dot3(bp, bp);
  if (d6 >= 0.0f && d5 <= d6) return dot3(cp, cp);
  const float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return edge_distance2(ap, ab, d1 / (d1 - d3));
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return edge_distance2(ap, ac, d2 / (d2 - d6));
  if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f)
    return edge_distance2(bp, c - b, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float h = dot3(ap, n);
  return h * h;
}

// What the brick test needs besides the triangle (BrickPairParams::reach): the margin, half the span
// of a brick's voxel centres, and the squared radius around a brick centre that holds every voxel
// centre within the margin of the brick's. A brick's voxel centres fill a cube of side brick - 1
// around its centre c, all within (brick - 1) / 2 * sqrt(3) of c; one lies within the margin of the
// triangle only if c lies within margin + (brick - 1) / 2 * |n|_1 of its plane and within
// margin + (brick - 1) / 2 * sqrt(3) of it.
struct PairReach {
  float margin, half_span, ball2;
};
PairReach pair_reach(double margin, int brick) {
  const float m = static_cast<float>(margin), half = 0.5f * static_cast<float>(brick - 1);
  const float ball = m + half * std::sqrt(3.0f);
  return {m, half, ball * ball};
}

// Appends triangle t's bricks (brick_pairs.comp's brick_box and brick_reached) to `out`.
void pair_triangle(const gpu::layout::SdfTriangle& t, std::uint32_t index, const Eigen::Vector3i& bricks,
                   const Eigen::Vector3i& dims, const PairReach& r, int side, std::vector<PairEntry>& out) {
  if (t.face_normal.w == 0.0f) return;
  const Vec3f v[3] = {xyz(t.vertex[0]), xyz(t.vertex[1]), xyz(t.vertex[2])};
  const float lo[3] = {std::min(std::min(v[0].x, v[1].x), v[2].x) - r.margin,
                       std::min(std::min(v[0].y, v[1].y), v[2].y) - r.margin,
                       std::min(std::min(v[0].z, v[1].z), v[2].z) - r.margin};
  const float hi[3] = {std::max(std::max(v[0].x, v[1].x), v[2].x) + r.margin,
                       std::max(std::max(v[0].y, v[1].y), v[2].y) + r.margin,
                       std::max(std::max(v[0].z, v[1].z), v[2].z) + r.margin};
  int b0[3], b1[3];
  for (int a = 0; a < 3; ++a) {
    if (hi[a] < 0.0f || lo[a] > static_cast<float>(dims[a] - 1)) return;  // misses the grid along a
    const float top = static_cast<float>(bricks[a] - 1), brick = static_cast<float>(side);
    b0[a] = static_cast<int>(std::clamp(std::floor(lo[a] / brick), 0.0f, top));
    b1[a] = static_cast<int>(std::clamp(std::floor(hi[a] / brick), 0.0f, top));
  }
  const Vec3f n = xyz(t.face_normal);
  const float plane_reach = r.margin + r.half_span * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
  for (int bz = b0[2]; bz <= b1[2]; ++bz)
    for (int by = b0[1]; by <= b1[1]; ++by)
      for (int bx = b0[0]; bx <= b1[0]; ++bx) {
        const float brick = static_cast<float>(side);
        const Vec3f centre = {static_cast<float>(bx) * brick + r.half_span, static_cast<float>(by) * brick + r.half_span,
                              static_cast<float>(bz) * brick + r.half_span};
        if (std::abs(dot3(n, centre - v[0])) > plane_reach ||
            triangle_distance2(centre, v[0], v[1], v[2], n) > r.ball2)
          continue;
        out.push_back({static_cast<std::uint32_t>(bz), index,
                       static_cast<std::uint32_t>(bx) | (static_cast<std::uint32_t>(by) << 16)});
      }
}

Eigen::Vector3i brick_counts(const GridSpec& spec, int brick) {
  const Eigen::Vector3i bricks = (spec.dims.array() + (brick - 1)) / brick;
  if (bricks.x() > 0xFFFF || bricks.y() > 0xFFFF) {
    throw GpuError(
        fmt::format("SDF grid {} x {} (x by y) has more than 65535 voxel bricks a side for the compute "
                    "scan conversion; use --scan geometry or a larger voxel",
                    spec.dims.x(), spec.dims.y()));
  }
  return bricks;
}

void check_pair_count(std::uint64_t count) {
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    throw GpuError(
        fmt::format("{} triangle/brick pairs exceed the 2^32 the compute scan conversion numbers; use "
                    "--scan geometry or a larger voxel",
                    count));
  }
}

// Exclusive prefix sum of the row totals with the grand total last, checked against 32 bits.
std::vector<std::uint32_t> row_starts(std::span<const std::uint32_t> row_counts) {
  std::vector<std::uint32_t> begin(row_counts.size() + 1, 0);
  std::uint64_t total = 0;
  for (std::size_t r = 0; r < row_counts.size(); ++r) {
    begin[r] = static_cast<std::uint32_t>(total);
    total += row_counts[r];
    check_pair_count(total);
  }
  begin.back() = static_cast<std::uint32_t>(total);
  return begin;
}

}  // namespace

int compute_brick_side(bool software_renderer) { return software_renderer ? 2 : 4; }

BrickPairs build_brick_pairs(std::span<const gpu::layout::SdfTriangle> triangles,
                             std::span<const std::uint32_t> usable, const GridSpec& spec, double margin,
                             int brick) {
  const Eigen::Vector3i bricks = brick_counts(spec, brick);
  const PairReach reach = pair_reach(margin, brick);
  std::vector<PairEntry> entries;
  for (std::uint32_t t : usable) pair_triangle(triangles[t], t, bricks, spec.dims, reach, brick, entries);
  check_pair_count(entries.size());
  // A counting sort by row keeps the triangles ascending within each row.
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(bricks.z()), 0);
  for (const PairEntry& e : entries) ++counts[e.row];
  BrickPairs pairs;
  pairs.brick = brick;
  pairs.row_begin = row_starts(counts);
  std::vector<std::uint32_t> cursor(pairs.row_begin.begin(), pairs.row_begin.end() - 1);
  pairs.words.resize(2 * entries.size());
  for (const PairEntry& e : entries) {
    const std::size_t slot = cursor[e.row]++;
    pairs.words[2 * slot] = e.triangle;
    pairs.words[2 * slot + 1] = e.key;
  }
  return pairs;
}

BrickPairs GpuBrickPairs::download() const {
  BrickPairs out;
  out.brick = brick;
  out.row_begin = row_begin;
  out.words = pairs.read<std::uint32_t>(2 * count());
  return out;
}

BrickPairGenerator::BrickPairGenerator(const gpu::ShaderLibrary& library)
    : spans_(gpu::Program::compute(library, "sdf/brick_pairs.comp", {"ROW_SPANS 1"})),
      count_(gpu::Program::compute(library, "sdf/brick_pairs.comp", {"COUNT 1"})),
      scatter_(gpu::Program::compute(library, "sdf/brick_pairs.comp", {"SCATTER 1"})),
      scan_(library) {}

GpuBrickPairs BrickPairGenerator::run(gpu::Queue& queue, const gpu::Buffer& triangles, std::uint32_t count,
                                      const GridSpec& spec, double margin, int brick) {
  const Eigen::Vector3i bricks = brick_counts(spec, brick);
  const PairReach reach = pair_reach(margin, brick);
  GpuBrickPairs out;
  out.brick = brick;
  out.row_begin.assign(static_cast<std::size_t>(bricks.z()) + 1, 0);
  out.pairs = gpu::Buffer(2 * sizeof(std::uint32_t));  // a bound buffer may not be empty
  if (count == 0) return out;
  params_.values = {{spec.dims.x(), spec.dims.y(), spec.dims.z(), brick},
                    {bricks.x(), bricks.y(), bricks.z(), 0},
                    {count, 0u, 0u, 0u},
                    {reach.margin, reach.half_span, reach.ball2, 0.0f}};
  triangles.bind(TS_SDF_TRIANGLES);
  gpu::Buffer spans(count * sizeof(std::uint32_t));
  spans.bind(TS_SDF_PAIR_SPANS);
  params_.bind(TS_SDF_PAIR_PARAMS);
  queue.dispatch_items(spans_, count);
  // The last span, read before the scan overwrites it, plus the last offset: the triangle rows.
  const std::uint32_t last_span = spans.read<std::uint32_t>(1, count - 1)[0];
  scan_.run(queue, spans, count);
  const std::size_t triangle_rows = spans.read<std::uint32_t>(1, count - 1)[0] + std::size_t{last_span};
  gpu::Buffer places(std::max<std::size_t>(triangle_rows, 1) * sizeof(std::uint32_t));
  gpu::Buffer rows(static_cast<std::size_t>(bricks.z()) * sizeof(std::uint32_t));
  rows.fill_zero();
  triangles.bind(TS_SDF_TRIANGLES);
  spans.bind(TS_SDF_PAIR_SPANS);
  places.bind(TS_SDF_PAIR_TRIANGLE_ROWS);
  rows.bind(TS_SDF_PAIR_ROW_COUNTS);
  params_.bind(TS_SDF_PAIR_PARAMS);  // again: the scan's own parameters took the slot
  queue.dispatch_items(count_, count);
  // The row totals are all that comes back; their prefix sum goes up again as the row starts.
  out.row_begin = row_starts(rows.read<std::uint32_t>(static_cast<std::size_t>(bricks.z())));
  rows.upload(std::span<const std::uint32_t>(out.row_begin).first(static_cast<std::size_t>(bricks.z())));
  out.pairs = gpu::Buffer(std::max<std::size_t>(out.count(), 1) * 2 * sizeof(std::uint32_t));
  out.pairs.bind(TS_SDF_PAIRS_OUT);
  queue.dispatch_items(scatter_, count);
  return out;
}

ComputeScan::ComputeScan(const gpu::ShaderLibrary& library, GpuBrickPairs pairs, const GridSpec& spec,
                         int slab_layers, double band)
    : spec_(spec),
      band_(static_cast<float>(band)),
      brick_(pairs.brick),
      row_begin_(pairs.row_begin),
      count_pass_(gpu::Program::compute(library, "sdf/scan_bricks.comp",
                                        {"BRICK " + std::to_string(pairs.brick), "BRICK_COUNT 1"})),
      scatter_pass_(gpu::Program::compute(library, "sdf/scan_bricks.comp",
                                          {"BRICK " + std::to_string(pairs.brick), "BRICK_SCATTER 1"})),
      brick_pass_(gpu::Program::compute(library, "sdf/scan_bricks.comp", {"BRICK " + std::to_string(pairs.brick)})),
      scan_(library),
      pairs_(std::move(pairs.pairs)),
      rows_(gpu::Buffer::from<std::uint32_t>(pairs.row_begin)) {
  // A slab of `slab_layers` layers spans at most this many brick rows (it need not start on one).
  const std::size_t rows = static_cast<std::size_t>((slab_layers + brick_ - 1) / brick_ + 1);
  const std::size_t per_row = static_cast<std::size_t>((spec.dims.x() + brick_ - 1) / brick_) *
                              static_cast<std::size_t>((spec.dims.y() + brick_ - 1) / brick_);
  reserve(rows * per_row, 1);
}

void ComputeScan::reserve(std::size_t bricks, std::size_t pairs) {
  if (brick_starts_.bytes() < (bricks + 1) * sizeof(std::uint32_t))
    brick_starts_ = gpu::Buffer((bricks + 1) * sizeof(std::uint32_t));
  if (pair_slots_.bytes() < pairs * sizeof(std::uint32_t)) {
    pair_slots_ = gpu::Buffer(pairs * sizeof(std::uint32_t));
    brick_triangles_ = gpu::Buffer(pairs * sizeof(std::uint32_t));
  }
}

std::size_t ComputeScan::fill(gpu::Queue& queue, const gpu::Buffer& triangles, const gpu::Texture& target,
                              int z0, int layers) {
  const std::size_t first_row = static_cast<std::size_t>(z0 / brick_);
  const std::size_t last_row = static_cast<std::size_t>((z0 + layers - 1) / brick_);
  const std::uint32_t first = row_begin_[first_row], count = row_begin_[last_row + 1] - first;
  if (count == 0) return 0;  // the target keeps its clear value everywhere
  const std::uint32_t bricks = static_cast<std::uint32_t>(last_row - first_row + 1) *
                               static_cast<std::uint32_t>((spec_.dims.x() + brick_ - 1) / brick_) *
                               static_cast<std::uint32_t>((spec_.dims.y() + brick_ - 1) / brick_);
  reserve(bricks, count);
  brick_starts_.fill_zero();  // the counts start at zero, and the entry past the last brick stays 0
  params_.values = {{spec_.dims.x(), spec_.dims.y(), spec_.dims.z(), static_cast<int>(row_begin_.size() - 1)},
                    {z0, layers, static_cast<int>(first_row), 0},
                    {first, count, bricks, 0u},
                    {band_, 0.0f, 0.0f, 0.0f}};
  // Each brick's pairs counted, the counts scanned into starts, the triangles listed per brick.
  auto bind = [&] {
    params_.bind(TS_SDF_COMPUTE_PARAMS);
    pairs_.bind(TS_SDF_PAIRS);
    rows_.bind(TS_SDF_PAIR_ROWS);
    pair_slots_.bind(TS_SDF_PAIR_SLOTS);
    brick_starts_.bind(TS_SDF_BRICK_STARTS);
    brick_triangles_.bind(TS_SDF_BRICK_TRIANGLES);
  };
  bind();
  queue.dispatch_items(count_pass_, count);
  scan_.run(queue, brick_starts_, bricks + 1);
  bind();  // the scan took some of the same slots
  queue.dispatch_items(scatter_pass_, count);
  triangles.bind(TS_SDF_TRIANGLES);
  const gpu::ImageBinding image(TS_SDF_IMAGE_SLAB, target, GL_WRITE_ONLY);
  // The band compaction reads the target through a sampler.
  queue.dispatch_groups(brick_pass_, bricks, GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  return count;
}

}  // namespace ts::sdf
