#pragma once
// SplitMix64 (Steele, Lea & Flood 2014): a 64-bit mix whose outputs pass BigCrush, used to seed
// generators and to draw reproducible values from a key alone (a probe's chunk, a bond's spheres).
#include <cstdint>

namespace ts {

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace ts
