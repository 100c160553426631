#include "sdf/inside_outside.h"

#include <cassert>
#include <cmath>
#include <cstdint>

namespace ts::sdf {
namespace {

enum State : std::uint8_t { kBand, kUnvisited, kSeen, kDone };

// Depth-first flood over the 6-connected voxels in state `from`, moving each to state `to`.
// on_voxel(index) sees every voxel of the region, on_band(index) every band voxel next to it (once
// per adjacency). The stack holds voxel indices, so memory follows the region's frontier.
class Flood {
 public:
  Flood(const GridSpec& spec, std::vector<std::uint8_t>& state) : spec_(spec), state_(state) {}

  template <class OnVoxel, class OnBand>
  void run(std::size_t seed, State from, State to, OnVoxel&& on_voxel, OnBand&& on_band) {
    const std::size_t nx = static_cast<std::size_t>(spec_.dims.x()), ny = static_cast<std::size_t>(spec_.dims.y()),
                      nz = static_cast<std::size_t>(spec_.dims.z());
    const std::size_t stride_y = nx, stride_z = nx * ny;
    stack_.clear();
    state_[seed] = to;
    stack_.push_back(seed);
    auto visit = [&](std::size_t n) {
      if (state_[n] == from) {
        state_[n] = to;
        stack_.push_back(n);
      } else if (state_[n] == kBand) {
        on_band(n);
      }
    };
    while (!stack_.empty()) {
      const std::size_t v = stack_.back();
      stack_.pop_back();
      on_voxel(v);
      const std::size_t i = v % nx, j = (v / nx) % ny, k = v / stride_z;
      if (i > 0) visit(v - 1);
      if (i + 1 < nx) visit(v + 1);
      if (j > 0) visit(v - stride_y);
      if (j + 1 < ny) visit(v + stride_y);
      if (k > 0) visit(v - stride_z);
      if (k + 1 < nz) visit(v + stride_z);
    }
  }

 private:
  const GridSpec& spec_;
  std::vector<std::uint8_t>& state_;
  std::vector<std::size_t> stack_;
};

bool on_border(const GridSpec& spec, int i, int j, int k) {
  return i == 0 || j == 0 || k == 0 || i == spec.dims.x() - 1 || j == spec.dims.y() - 1 || k == spec.dims.z() - 1;
}

}  // namespace

InsideOutsideStats fill_outside_band_signs(const GridSpec& spec, std::vector<float>& values, float band_world) {
  assert(values.size() == spec.voxel_count());
  assert(band_world > 0.0f);
  InsideOutsideStats stats;
  std::vector<std::uint8_t> state(values.size());
  for (std::size_t v = 0; v < values.size(); ++v) state[v] = std::isfinite(values[v]) ? kBand : kUnvisited;
  Flood flood(spec, state);
  auto ignore = [](std::size_t) {};

  // Regions reaching the border: outside. Only border voxels can seed them.
  for (int k = 0; k < spec.dims.z(); ++k)
    for (int j = 0; j < spec.dims.y(); ++j)
      for (int i = 0; i < spec.dims.x(); ++i) {
        if (!on_border(spec, i, j, k)) {
          i = spec.dims.x() - 2;  // the rest of an inner row is inner, up to its last voxel
          continue;
        }
        const std::size_t seed = spec.linear_index(i, j, k);
        if (state[seed] != kUnvisited) continue;
        ++stats.regions;
        flood.run(seed, kUnvisited, kDone, [&](std::size_t v) { values[v] = band_world; ++stats.outside_voxels; }, ignore);
      }

  // Enclosed regions: the sign their band neighbours vote for, inside on a tie. Two passes over each
  // region (vote, then write) keep memory at one byte per voxel.
  for (std::size_t seed = 0; seed < values.size(); ++seed) {
    if (state[seed] != kUnvisited) continue;
    ++stats.regions;
    std::size_t positive = 0, negative = 0;
    flood.run(seed, kUnvisited, kSeen, ignore, [&](std::size_t band) { ++(values[band] > 0.0f ? positive : negative); });
    const bool cavity = positive > negative;
    stats.cavities += cavity ? 1 : 0;
    const float value = cavity ? band_world : -band_world;
    std::size_t& count = cavity ? stats.outside_voxels : stats.inside_voxels;
    flood.run(seed, kSeen, kDone, [&](std::size_t v) { values[v] = value; ++count; }, ignore);
  }
  return stats;
}

}  // namespace ts::sdf
