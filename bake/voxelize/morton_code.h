// 64-bit Morton codes: 21 bits per axis interleaved so that bit 3i is x's bit i, bit 3i+1 is y's,
// bit 3i+2 is z's. Read from the top, each 3-bit triplet of a leaf's code is the octant index
// (bit 0 = +x, bit 1 = +y, bit 2 = +z) of the node at one level, the same octant convention as
// formats::svo_find_node, so sorting codes sorts voxels into the octree's breadth-first child order.
#pragma once
#include <cstdint>

namespace exitance::morton {

constexpr uint32_t kBitsPerAxis = 21;

// Inserts two zero bits above each of the low 21 bits of v (magic-number bit spreading).
inline uint64_t spread_bits_by_three(uint32_t v) {
  uint64_t x = v & 0x1FFFFFu;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// Inverse of spread_bits_by_three: gathers every third bit starting at bit 0.
inline uint32_t compact_bits_by_three(uint64_t x) {
  x &= 0x1249249249249249ull;
  x = (x | x >> 2) & 0x10C30C30C30C30C3ull;
  x = (x | x >> 4) & 0x100F00F00F00F00Full;
  x = (x | x >> 8) & 0x1F0000FF0000FFull;
  x = (x | x >> 16) & 0x1F00000000FFFFull;
  x = (x | x >> 32) & 0x1FFFFFull;
  return uint32_t(x);
}

inline uint64_t encode(uint32_t x, uint32_t y, uint32_t z) {
  return spread_bits_by_three(x) | (spread_bits_by_three(y) << 1) | (spread_bits_by_three(z) << 2);
}

struct Cell {
  uint32_t x, y, z;
};
inline Cell decode(uint64_t code) {
  return {compact_bits_by_three(code), compact_bits_by_three(code >> 1), compact_bits_by_three(code >> 2)};
}

// Octant (0..7) of the level-`level` ancestor of a depth-`depth` leaf code within its parent, 1 <= level <= depth.
inline uint32_t octant_at_level(uint64_t leaf_code, uint32_t level, uint32_t depth) {
  return uint32_t(leaf_code >> (3 * (depth - level))) & 7u;
}

}  // namespace exitance::morton
