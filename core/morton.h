#pragma once
// Morton (Z-order) codes of 3D cells: the bits of x, y and z interleaved, so cells near each other
// mostly get codes near each other. Sorting by them puts neighbours near each other in memory (the
// CPU reference's contact lists, the CPU relaxer's particle order).
#include <cstdint>

namespace ts {

// Bits 0, 3, 6, ... of the result are bits 0, 1, 2, ... of v; v's bits above 20 are dropped.
constexpr std::uint64_t spread_bits_3d(std::uint64_t v) {
  v &= 0x1fffffu;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

// The Morton code of cell (x, y, z), each coordinate's low 21 bits.
constexpr std::uint64_t morton_code(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  return spread_bits_3d(x) | spread_bits_3d(y) << 1 | spread_bits_3d(z) << 2;
}
static_assert(morton_code(1, 0, 0) == 1 && morton_code(0, 1, 0) == 2 && morton_code(0, 0, 1) == 4);
static_assert(morton_code(3, 3, 3) == 63);

}  // namespace ts
