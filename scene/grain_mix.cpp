// Grain types and sizes of an emitter's grains: exact counts by largest remainder, a portable shuffle,
// per-grain uniform and lognormal scales.
#include "scene/grain_mix.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>

namespace ts::scene {
namespace {

// The size draws' own stream, apart from the seed's jitter and orientation stream.
constexpr std::uint64_t kDrawStream = 0x9E3779B97F4A7C15ull;

// std::mt19937_64's output is fixed by the standard; the distributions of <random> are not, so the
// draws are made here from its bits.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }

double standard_normal(std::mt19937_64& rng) {  // Box-Muller
  const double u = 1.0 - uniform01(rng), v = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
}

// `count` split in proportion to `weights` (not all zero): floors, then the largest remainders.
std::vector<std::size_t> apportion(const std::vector<double>& weights, std::size_t count) {
  double total = 0;
  for (double w : weights) total += w;
  std::vector<std::size_t> out(weights.size());
  std::vector<std::pair<double, std::size_t>> remainders;
  std::size_t given = 0;
  for (std::size_t k = 0; k < weights.size(); ++k) {
    const double exact = weights[k] / total * static_cast<double>(count);
    out[k] = static_cast<std::size_t>(std::floor(exact));
    given += out[k];
    remainders.emplace_back(exact - std::floor(exact), k);
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t i = 0; given < count; ++i, ++given) ++out[remainders[i % remainders.size()].second];
  return out;
}

double draw_scale(const SizeSpec& size, std::mt19937_64& rng) {
  if (size.distribution == SizeDistribution::Uniform)
    return size.min + (size.max - size.min) * uniform01(rng);
  if (!(size.min < size.max)) return size.min;  // a window of one scale (the parser refuses it)
  for (;;) {  // lognormal, redrawn outside [min, max] (which hold the median, so this ends)
    const double s = size.median * std::exp(size.sigma * standard_normal(rng));
    if (s >= size.min && s <= size.max) return s;
  }
}

std::string describe(const Scene& scene, std::uint16_t type, double scale, bool sizes_vary) {
  const std::string& name = scene.grains[type].name;
  std::string out =
      scene.grains.size() > 1 || !name.empty() ? fmt::format("a grain of type \"{}\"", name) : "a grain";
  if (sizes_vary || scale != 1) out += fmt::format(" at scale {:.3g}", scale);
  return out;
}

}  // namespace

std::pair<double, double> scale_range(const SizeSpec& size) {
  switch (size.distribution) {
    case SizeDistribution::None:
      return {1.0, 1.0};
    case SizeDistribution::Sieve: {
      double lo = 1e300, hi = 0;
      for (const auto& [scale, fraction] : size.sieve) {
        if (fraction <= 0) continue;
        lo = std::min(lo, scale);
        hi = std::max(hi, scale);
      }
      return {lo, hi};
    }
    default:
      return {size.min, size.max};
  }
}

std::vector<GrainDraw> emitter_grain_draws(const Emitter& e) {
  std::mt19937_64 rng(e.seed ^ kDrawStream);
  std::vector<GrainDraw> draws;
  draws.reserve(e.count);
  const std::vector<std::size_t> per_type = apportion(e.fractions, e.count);
  for (std::size_t t = 0; t < per_type.size(); ++t) {
    if (e.size.distribution != SizeDistribution::Sieve) {
      draws.insert(draws.end(), per_type[t], GrainDraw{e.grains[t], 1.0});
      continue;
    }
    std::vector<double> numbers;  // number share of each class: mass share / scale^3
    for (const auto& [scale, fraction] : e.size.sieve) numbers.push_back(fraction / (scale * scale * scale));
    const std::vector<std::size_t> per_class = apportion(numbers, per_type[t]);
    for (std::size_t k = 0; k < per_class.size(); ++k)
      draws.insert(draws.end(), per_class[k], GrainDraw{e.grains[t], e.size.sieve[k].first});
  }
  for (std::size_t i = draws.size(); i > 1; --i) std::swap(draws[i - 1], draws[rng() % i]);  // Fisher-Yates
  const bool drawn =
      e.size.distribution == SizeDistribution::Uniform || e.size.distribution == SizeDistribution::Lognormal;
  if (drawn)
    for (GrainDraw& d : draws) d.scale = draw_scale(e.size, rng);
  return draws;
}

GrainShape scaled_grain(const Scene& scene, std::uint16_t type, double scale) {
  const GrainSpec& g = scene.grains[type];
  return make_tetrahedral_grain(scale * g.radius, scale * g.edge, scene.materials[g.material].density);
}

double emitter_bound(const Scene& scene, const Emitter& e) {
  const double largest = scale_range(e.size).second;
  double bound = 0;
  for (std::uint16_t t : e.grains) bound = std::max(bound, scaled_grain(scene, t, largest).bounding_radius);
  return bound;
}

std::vector<GrainKind> scene_grain_kinds(const Scene& scene) {
  std::map<std::uint16_t, std::pair<double, double>> ranges;  // type -> smallest, largest scale
  for (const Emitter& e : scene.emitters) {
    const auto [lo, hi] = scale_range(e.size);
    for (std::size_t k = 0; k < e.grains.size(); ++k) {
      if (e.fractions[k] <= 0) continue;
      auto [it, fresh] = ranges.try_emplace(e.grains[k], lo, hi);
      if (!fresh) it->second = {std::min(it->second.first, lo), std::max(it->second.second, hi)};
    }
  }
  if (scene.emitters.empty())
    for (std::uint16_t t = 0; t < scene.grains.size(); ++t) ranges.try_emplace(t, 1.0, 1.0);
  bool vary = false;
  for (const auto& [type, range] : ranges) vary = vary || range.first != range.second;
  std::vector<GrainKind> kinds;
  for (const auto& [type, range] : ranges) {
    for (double scale : {range.first, range.second}) {
      if (!kinds.empty() && kinds.back().type == type && kinds.back().scale == scale) continue;
      kinds.push_back({type, scale, scaled_grain(scene, type, scale), describe(scene, type, scale, vary)});
    }
  }
  return kinds;
}

}  // namespace ts::scene
