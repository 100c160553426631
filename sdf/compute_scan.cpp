#include "sdf/compute_scan.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "shaders/sdf/bindings.h"

namespace ts::sdf {
namespace {

struct PairEntry {
  std::uint32_t row, triangle, key;
};

Eigen::Vector3d vertex_of(const gpu::layout::SdfTriangle& t, int k) {
  return {t.vertex[k].x, t.vertex[k].y, t.vertex[k].z};
}

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection, 5.1.5), in double.
double triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a, bp = p - b, cp = p - c;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap), d3 = ab.dot(bp), d4 = ac.dot(bp), d5 = ab.dot(cp),
               d6 = ac.dot(cp);
  if (d1 <= 0 && d2 <= 0) return ap.norm();
  if (d3 >= 0 && d4 <= d3) return bp.norm();
  if (d6 >= 0 && d5 <= d6) return cp.norm();
  const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + ab * (d1 / (d1 - d3)))).norm();
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + ac * (d2 / (d2 - d6)))).norm();
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).norm();
  const double denominator = va + vb + vc;
  // A sliver whose barycentric denominator vanishes: its edges already bound the distance above.
  if (!(std::abs(denominator) > 0.0)) return 0.0;
  return (p - (a + ab * (vb / denominator) + ac * (vc / denominator))).norm();
}

// Appends triangle t's bricks (side `brick`) to `out`. A brick's voxel centres fill a cube of side
// brick - 1 around its centre c, all within (brick - 1) / 2 * sqrt(3) of c; one lies within `margin` of
// the triangle only if the cube meets the slab |n.(x - v0)| <= margin, i.e. |n.(c - v0)| <= margin +
// (brick - 1) / 2 * |n|_1 (a cheap first test), and c lies within margin + (brick - 1) / 2 * sqrt(3) of it.
void pair_triangle(const gpu::layout::SdfTriangle& t, std::uint32_t index, const Eigen::Vector3i& bricks,
                   const Eigen::Vector3i& dims, double margin, int kBrick, std::vector<PairEntry>& out) {
  const Eigen::Vector3d v[3] = {vertex_of(t, 0), vertex_of(t, 1), vertex_of(t, 2)};
  const Eigen::Vector3d lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]).array() - margin;
  const Eigen::Vector3d hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]).array() + margin;
  Eigen::Vector3i b0, b1;
  for (int a = 0; a < 3; ++a) {
    if (hi[a] < 0.0 || lo[a] > dims[a] - 1) return;  // wholly outside the grid along this axis
    b0[a] = std::clamp(static_cast<int>(std::floor(lo[a] / kBrick)), 0, bricks[a] - 1);
    b1[a] = std::clamp(static_cast<int>(std::floor(hi[a] / kBrick)), 0, bricks[a] - 1);
  }
  const Eigen::Vector3d n(t.face_normal.x, t.face_normal.y, t.face_normal.z);
  const double reach = margin + 0.5 * (kBrick - 1) * n.cwiseAbs().sum();
  const double ball = margin + 0.5 * (kBrick - 1) * std::sqrt(3.0);
  for (int bz = b0.z(); bz <= b1.z(); ++bz)
    for (int by = b0.y(); by <= b1.y(); ++by)
      for (int bx = b0.x(); bx <= b1.x(); ++bx) {
        const Eigen::Vector3d centre =
            Eigen::Vector3d(bx, by, bz) * kBrick + Eigen::Vector3d::Constant(0.5 * (kBrick - 1));
        if (std::abs(n.dot(centre - v[0])) > reach || triangle_distance(centre, v[0], v[1], v[2]) > ball)
          continue;
        out.push_back({static_cast<std::uint32_t>(bz), index,
                       static_cast<std::uint32_t>(bx) | (static_cast<std::uint32_t>(by) << 16)});
      }
}

}  // namespace

int compute_brick_side(bool software_renderer) { return software_renderer ? 2 : 4; }

BrickPairs build_brick_pairs(std::span<const gpu::layout::SdfTriangle> triangles,
                             std::span<const std::uint32_t> usable, const GridSpec& spec, double margin,
                             int brick) {
  const int kBrick = brick;
  const Eigen::Vector3i bricks = (spec.dims.array() + (kBrick - 1)) / kBrick;
  if (bricks.x() > 0xFFFF || bricks.y() > 0xFFFF) {
    throw GpuError(
        fmt::format("SDF grid {} x {} (x by y) has more than 65535 voxel bricks a side for the compute "
                    "scan conversion; use --scan geometry or a larger voxel",
                    spec.dims.x(), spec.dims.y()));
  }
  std::vector<PairEntry> entries;
  for (std::uint32_t t : usable) pair_triangle(triangles[t], t, bricks, spec.dims, margin, kBrick, entries);
  if (entries.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw GpuError(
        fmt::format("{} triangle/brick pairs exceed the 2^32 the compute scan conversion numbers; use "
                    "--scan geometry or a larger voxel",
                    entries.size()));
  }
  // A counting sort by row keeps the triangles ascending within each row.
  BrickPairs pairs;
  pairs.brick = brick;
  pairs.row_begin.assign(static_cast<std::size_t>(bricks.z()) + 1, 0);
  for (const PairEntry& e : entries) ++pairs.row_begin[e.row + 1];
  for (std::size_t r = 1; r < pairs.row_begin.size(); ++r) pairs.row_begin[r] += pairs.row_begin[r - 1];
  std::vector<std::uint32_t> cursor(pairs.row_begin.begin(), pairs.row_begin.end() - 1);
  pairs.words.resize(2 * entries.size());
  for (const PairEntry& e : entries) {
    const std::size_t slot = cursor[e.row]++;
    pairs.words[2 * slot] = e.triangle;
    pairs.words[2 * slot + 1] = e.key;
  }
  return pairs;
}

ComputeScan::ComputeScan(const gpu::ShaderLibrary& library, const BrickPairs& pairs, const GridSpec& spec,
                         int slab_layers, double band)
    : spec_(spec),
      band_(static_cast<float>(band)),
      brick_(pairs.brick),
      row_begin_(pairs.row_begin),
      nearest_distance_pass_(
          gpu::Program::compute(library, "sdf/scan_pairs.comp", {"BRICK " + std::to_string(pairs.brick)})),
      nearest_triangle_pass_(gpu::Program::compute(
          library, "sdf/scan_pairs.comp", {"BRICK " + std::to_string(pairs.brick), "NEAREST_TRIANGLE 1"})),
      write_pass_(gpu::Program::compute(library, "sdf/scan_write.comp")),
      pairs_(gpu::Buffer::from<std::uint32_t>(pairs.words)),
      rows_(gpu::Buffer::from<std::uint32_t>(pairs.row_begin)),
      nearest_distance_(static_cast<std::size_t>(spec.dims.x()) * static_cast<std::size_t>(spec.dims.y()) *
                        static_cast<std::size_t>(slab_layers) * sizeof(std::uint32_t)),
      nearest_triangle_(nearest_distance_.bytes()) {}

std::size_t ComputeScan::fill(gpu::Queue& queue, const gpu::Texture& target, int z0, int layers) {
  const std::size_t first_row = static_cast<std::size_t>(z0 / brick_);
  const std::size_t last_row = static_cast<std::size_t>((z0 + layers - 1) / brick_);
  const std::uint32_t first = row_begin_[first_row], count = row_begin_[last_row + 1] - first;
  const std::uint32_t voxels = static_cast<std::uint32_t>(spec_.dims.x()) *
                               static_cast<std::uint32_t>(spec_.dims.y()) *
                               static_cast<std::uint32_t>(layers);
  if (count == 0) return 0;  // the target keeps its clear value everywhere
  // Zero reads "no triangle yet" in both (the kernels store complements).
  nearest_distance_.fill_zero();
  nearest_triangle_.fill_zero();
  params_.values = {{spec_.dims.x(), spec_.dims.y(), spec_.dims.z(), static_cast<int>(row_begin_.size() - 1)},
                    {z0, layers, 0, 0},
                    {first, count, voxels, 0u},
                    {band_, 0.0f, 0.0f, 0.0f}};
  params_.bind(TS_SDF_COMPUTE_PARAMS);
  pairs_.bind(TS_SDF_PAIRS);
  rows_.bind(TS_SDF_PAIR_ROWS);
  nearest_distance_.bind(TS_SDF_NEAREST_DISTANCE);
  nearest_triangle_.bind(TS_SDF_NEAREST_TRIANGLE);
  queue.dispatch_groups(nearest_distance_pass_, count);
  queue.dispatch_groups(nearest_triangle_pass_, count);
  const gpu::ImageBinding image(TS_SDF_IMAGE_SLAB, target, GL_WRITE_ONLY);
  // The band compaction reads the target through a sampler.
  queue.dispatch_items(write_pass_, voxels,
                       GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  return count;
}

}  // namespace ts::sdf
