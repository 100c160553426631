#include "sim/cpu_lists.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <utility>

#include "core/morton.h"
#include "sim/contact_lists.h"
#include "sim/cpu_parallel.h"

namespace ts::sim {

namespace {

// Relative margin on the build's reach and cell, so that a pair the rebuild rule says cannot touch
// yet is not lost to the round-off of the distances compared at the build and at the step.
constexpr double kRoundOffMargin = 1e-9;

}  // namespace

std::uint32_t hash_cell(const Eigen::Vector3i& c, std::uint32_t table_size) {
  const std::uint32_t h = static_cast<std::uint32_t>(c.x()) + static_cast<std::uint32_t>(c.y()) * 19349663u +
                          static_cast<std::uint32_t>(c.z()) * 83492791u;
  return h & (table_size - 1u);
}

void build_neighbour_grid(const std::vector<Eigen::Vector3d>& positions, double cell_size,
                          NeighbourGrid& grid) {
  const auto n = static_cast<std::uint32_t>(positions.size());
  grid.cell_size = cell_size;
  // At least 4 buckets, so the three buckets of a row (CpuContactLists::search) are always distinct.
  grid.table_size = std::bit_ceil(std::max<std::uint32_t>(2 * n, 4));
  grid.cell.resize(n);
  std::vector<std::uint32_t> bucket(n);
  for_each_index(n, [&](std::uint32_t i) {
    // A blown-up state still gets a cell (NaN or huge coordinates would overflow the int cast);
    // the stability check rejects it after the step.
    const Eigen::Array3d cell = (positions[i] / cell_size).array().floor();
    grid.cell[i] = Eigen::Vector3i::Zero();
    if (cell.allFinite()) grid.cell[i] = cell.max(-1e9).min(1e9).cast<int>().matrix();
    bucket[i] = hash_cell(grid.cell[i], grid.table_size);
  });
  // Counting sort: count, exclusive scan, scatter in particle order (buckets list ids ascending).
  grid.bucket_start.assign(grid.table_size + 1, 0);
  for (std::uint32_t i = 0; i < n; ++i) ++grid.bucket_start[bucket[i] + 1];
  for (std::uint32_t b = 0; b < grid.table_size; ++b) grid.bucket_start[b + 1] += grid.bucket_start[b];
  std::vector<std::uint32_t> fill(grid.bucket_start.begin(), grid.bucket_start.end() - 1);
  grid.sorted.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) grid.sorted[fill[bucket[i]]++] = i;
}

bool CpuContactLists::stale(const std::vector<Eigen::Vector3d>& positions) const {
  if (!built_ || positions.size() != built_position_.size()) return true;
  // The largest squared displacement since the build; a non-finite one counts as infinite.
  auto largest_in = [&](std::size_t begin, std::size_t end, double m) {
    for (std::size_t i = begin; i < end; ++i) {
      const double d = (positions[i] - built_position_[i]).squaredNorm();
      m = std::isfinite(d) ? std::max(m, d) : std::numeric_limits<double>::infinity();
    }
    return m;
  };
  const double largest =
      positions.size() < kSerialBelow || one_thread()
          ? largest_in(0, positions.size(), 0.0)
          : tbb::parallel_reduce(
                tbb::blocked_range<std::size_t>(0, positions.size(), kSerialBelow / 4), 0.0,
                [&](const tbb::blocked_range<std::size_t>& r, double m) { return largest_in(r.begin(), r.end(), m); },
                [](double a, double b) { return std::max(a, b); });
  return lists_need_rebuild(std::sqrt(largest), skin_);
}

void CpuContactLists::build(const World& world, const std::vector<Eigen::Vector3d>& positions,
                            const StepSettings& settings) {
  double max_radius = 0;
  for (double r : world.particles.radius) max_radius = std::max(max_radius, r);
  largest_diameter_ = 2 * max_radius;
  skin_ = choose_skin(largest_diameter_, settings.design_speed, settings.dt, settings.skin);
  const double cell = (largest_diameter_ + skin_) * (1 + kRoundOffMargin);  // m
  build_neighbour_grid(positions, cell > 0 ? cell : 1.0, grid_);
  fill_grid_entries(world, positions);
  bonded_ = bonded_partners(world.bonds, positions.size());
  rest_ = rest_overlaps(world.bonds, positions.size());
  sort_by_cell();
  fill_lists();
  fill_pairs();
  built_position_ = positions;
  built_ = true;
  ++builds_;
}

void CpuContactLists::fill_grid_entries(const World& world, const std::vector<Eigen::Vector3d>& positions) {
  const Particles& p = world.particles;
  const auto n = static_cast<std::uint32_t>(positions.size());
  grid_entries_.resize(n);
  grid_slot_.resize(n);
  for_each_index(n, [&](std::uint32_t s) {
    const std::uint32_t j = grid_.sorted[s];
    const std::uint32_t body = p.body[j];
    grid_entries_[s] = {positions[j], p.radius[j], grid_.cell[j],
                        body,         j,           world.bodies.inverse_mass[body] != 0};
    grid_slot_[j] = s;
  });
  listed_ = 0;
  for (const GridEntry& e : grid_entries_) listed_ += e.receives_force ? 1 : 0;
}

// Morton order of the cells, relative to the lowest cell on each axis (21 bits an axis; a wider
// spread shares the last cell of the code, which only costs locality); ties by world id.
void CpuContactLists::sort_by_cell() {
  const auto n = static_cast<std::uint32_t>(grid_.cell.size());
  Eigen::Vector3i low = Eigen::Vector3i::Constant(std::numeric_limits<int>::max());
  for (const Eigen::Vector3i& c : grid_.cell) low = low.cwiseMin(c);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  for_each_index(n, [&](std::uint32_t i) {
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const std::int64_t from_low = std::int64_t{grid_.cell[i][axis]} - low[axis];
      key |= spread_bits_3d(static_cast<std::uint64_t>(std::min<std::int64_t>(from_low, 0x1fffff))) << axis;
    }
    keyed[i] = {key, i};
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  order_.resize(n);
  slot_.resize(n);
  for (std::uint32_t s = 0; s < n; ++s) {
    order_[s] = keyed[s].second;
    slot_[order_[s]] = s;
  }
}

// The 27 cells around, row by row (dz, dy): a row's three cells along x are three consecutive
// buckets (see hash_cell), so one contiguous scan unless it wraps around the table's end.
template <typename Fn>
void CpuContactLists::search(const GridEntry& self, Fn&& fn) const {
  const Eigen::Vector3i& own = self.cell;
  auto scan = [&](std::uint32_t first, std::uint32_t end, int y, int z) {
    for (std::uint32_t k = first; k < end; ++k) {
      const GridEntry& other = grid_entries_[k];
      // A cell of another row hashed here, or a pair that can take no force.
      if (other.cell.y() != y || other.cell.z() != z || std::abs(other.cell.x() - own.x()) > 1) continue;
      if (other.body == self.body || (!self.receives_force && !other.receives_force)) continue;
      if (!bonded_.empty() && bonded_.bonded(self.particle, other.particle)) continue;
      const double reach = (self.radius + other.radius + skin_) * (1 + kRoundOffMargin);  // m
      if ((self.position - other.position).squaredNorm() < reach * reach) fn(other.particle);
    }
  };
  const std::uint32_t last_bucket = grid_.table_size - 1;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      const int y = own.y() + dy, z = own.z() + dz;
      const std::uint32_t h = hash_cell(Eigen::Vector3i(own.x() - 1, y, z), grid_.table_size);
      if (h + 2 <= last_bucket) {
        scan(grid_.bucket_start[h], grid_.bucket_start[h + 3], y, z);
      } else {
        for (std::uint32_t k = 0; k < 3; ++k) {
          const std::uint32_t hk = (h + k) & last_bucket;
          scan(grid_.bucket_start[hk], grid_.bucket_start[hk + 1], y, z);
        }
      }
    }
  }
}

// The lists as one compact array (CSR) in cell order, each sorted by world id. On one thread each
// particle's search appends its list straight to the array. Split over threads, a counting pass sizes
// every list, then a filling pass searches again and writes each in its place: twice the search, but
// the lists are held once in memory (collecting them per thread and copying them into place cost a
// second copy of the lists, about 9 % more CPU memory at 64k grains).
void CpuContactLists::fill_lists() {
  const auto n = static_cast<std::uint32_t>(order_.size());
  offsets_.assign(std::size_t{n} + 1, 0);
  auto by_world_id = [](const ListEntry& a, const ListEntry& b) { return a.particle < b.particle; };
  if (n < kSerialBelow || one_thread()) {
    // Filled as a local (moved in and out, so it keeps its capacity: a build allocates only when the
    // lists outgrow the last ones), which the compiler need not reload after every store as it does a
    // member's: 3 % of the bed's run.
    std::vector<ListEntry> lists = std::move(entries_);
    lists.clear();
    for (std::uint32_t s = 0; s < n; ++s) {
      const GridEntry& self = grid_entries_[grid_slot_[order_[s]]];
      if (self.receives_force) {
        const std::size_t begin = lists.size();
        search(self, [&](std::uint32_t j) { lists.push_back({slot_[j], j}); });
        std::sort(lists.begin() + static_cast<std::ptrdiff_t>(begin), lists.end(), by_world_id);
      }
      offsets_[s + 1] = static_cast<std::uint32_t>(lists.size());
    }
    entries_ = std::move(lists);
    return;
  }
  for_each_index(n, [&](std::uint32_t s) {
    const GridEntry& self = grid_entries_[grid_slot_[order_[s]]];
    if (!self.receives_force) return;
    std::uint32_t count = 0;
    search(self, [&](std::uint32_t) { ++count; });
    offsets_[s + 1] = count;
  });
  for (std::uint32_t s = 0; s < n; ++s) offsets_[s + 1] += offsets_[s];
  entries_.resize(offsets_[n]);
  for_each_index(n, [&](std::uint32_t s) {
    const GridEntry& self = grid_entries_[grid_slot_[order_[s]]];
    if (!self.receives_force) return;
    ListEntry* out = entries_.data() + offsets_[s];
    search(self, [&](std::uint32_t j) { *out++ = {slot_[j], j}; });
    std::sort(entries_.data() + offsets_[s], out, by_world_id);
  });
}

bool CpuContactLists::first_of_pair(std::uint32_t particle, std::uint32_t partner) const {
  return !grid_entries_[grid_slot_[partner]].receives_force || particle < partner;
}

void CpuContactLists::fill_pairs() {
  const auto n = static_cast<std::uint32_t>(order_.size());
  // Pairs by first slot (CSR): count, scan, fill.
  std::vector<std::uint32_t> pair_offsets(std::size_t{n} + 1, 0);
  for_each_index(n, [&](std::uint32_t s) {
    for (const ListEntry& e : candidates(s)) pair_offsets[s + 1] += first_of_pair(order_[s], e.particle) ? 1 : 0;
  });
  for (std::uint32_t s = 0; s < n; ++s) pair_offsets[s + 1] += pair_offsets[s];
  pairs_.first.resize(pair_offsets[n]);
  pairs_.second.resize(pair_offsets[n]);
  for_each_index(n, [&](std::uint32_t s) {
    std::uint32_t p = pair_offsets[s];
    for (ListEntry& e : std::span(entries_.data() + offsets_[s], entries_.data() + offsets_[s + 1])) {
      e.first = first_of_pair(order_[s], e.particle);
      if (!e.first) continue;
      pairs_.first[p] = s;
      pairs_.second[p] = e.slot;
      e.pair = p++;
    }
  });
  pairs_.rest_overlap.clear();
  if (!rest_.empty()) {
    pairs_.rest_overlap.resize(pairs_.size());
    for_each_index(static_cast<std::uint32_t>(pairs_.size()), [&](std::uint32_t p) {
      pairs_.rest_overlap[p] = rest_.of(order_[pairs_.first[p]], order_[pairs_.second[p]]);
    });
  }
  // The second side's entry of each pair between two particles that take a force. The search is
  // symmetric (the same reach both ways), so the entry is there; a miss would be a bug here.
  const auto pair_count = static_cast<std::uint32_t>(pairs_.size());
  for_each_index(pair_count, [&](std::uint32_t p) {
    const std::uint32_t second = pairs_.second[p];
    const std::uint32_t first_particle = order_[pairs_.first[p]];
    ListEntry* begin = entries_.data() + offsets_[second];
    ListEntry* end = entries_.data() + offsets_[second + 1];
    if (!grid_entries_[grid_slot_[order_[second]]].receives_force) return;  // no list of its own
    ListEntry* e = std::lower_bound(begin, end, first_particle,
                                    [](const ListEntry& a, std::uint32_t id) { return a.particle < id; });
    if (e == end || e->particle != first_particle) {
      throw std::logic_error("CpuContactLists: a candidate pair is listed on one side only");
    }
    e->pair = p;
  });
}

}  // namespace ts::sim
