#include "preview/colors.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ts::preview {

Eigen::Vector3f viridis(double t) {
  // matplotlib's viridis at t = 0, 1/8, ..., 1.
  static constexpr std::array<std::array<float, 3>, 9> kStops{{{0.267f, 0.005f, 0.329f},
                                                               {0.283f, 0.141f, 0.458f},
                                                               {0.254f, 0.265f, 0.530f},
                                                               {0.207f, 0.372f, 0.553f},
                                                               {0.164f, 0.471f, 0.558f},
                                                               {0.128f, 0.567f, 0.551f},
                                                               {0.135f, 0.659f, 0.518f},
                                                               {0.478f, 0.821f, 0.318f},
                                                               {0.993f, 0.906f, 0.144f}}};
  const double x = std::clamp(std::isfinite(t) ? t : 1.0, 0.0, 1.0) * 8.0;
  const int i = std::min(static_cast<int>(x), 7);
  const float f = static_cast<float>(x - i);
  Eigen::Vector3f c;
  for (int k = 0; k < 3; ++k) c[k] = (1.0f - f) * kStops[i][k] + f * kStops[i + 1][k];
  return c;
}

std::uint32_t pack_rgba8(const Eigen::Vector3f& srgb) {
  std::uint32_t out = 0xff000000u;
  for (int k = 0; k < 3; ++k) {
    const auto byte = static_cast<std::uint32_t>(std::lround(std::clamp(srgb[k], 0.0f, 1.0f) * 255.0f));
    out |= byte << (8 * k);
  }
  return out;
}

Eigen::Vector3f categorical(std::uint32_t key) {
  const double hue = std::fmod(0.61803398875 * key, 1.0) * 6.0;  // sextants of the colour wheel
  const float s = key % 2 ? 0.55f : 0.75f, v = key % 3 == 1 ? 0.78f : 0.92f;
  const int sextant = static_cast<int>(hue) % 6;
  const float f = static_cast<float>(hue - std::floor(hue));
  const float p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (sextant) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

Eigen::Vector3f vary(const Eigen::Vector3f& srgb, std::uint32_t key, float amount) {
  // Integer hash (lowbias32, Wellons 2018): neighbouring keys get unrelated shades.
  std::uint32_t h = key;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  const float u = static_cast<float>(h & 0xffffu) / 65535.0f;  // 0..1
  return (srgb * (1.0f + amount * (2.0f * u - 1.0f))).cwiseMin(1.0f).cwiseMax(0.0f);
}

}  // namespace ts::preview
