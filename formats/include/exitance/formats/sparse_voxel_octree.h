// The sparse voxel octree (SVO) of a bake, in memory exactly as svo.bin stores it (svo_format.md):
// a cube over the scene, nodes in breadth-first order (all of level 0, then level 1, ...), the
// children of a node contiguous in octant order. Each node has a two-sided normal and the radiant
// exitance M = pi * L_o (RGB, W/m^2 in scene units) of each side; internal nodes hold the filtered
// (averaged) exitance of their subtree. 28 bytes per node.
#pragma once
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "exitance/formats/half_float.h"

namespace exitance::formats {

constexpr uint32_t kSvoNoParent = 0xFFFFFFFFu;
constexpr uint32_t kSvoMaxDepth = 16;

enum SvoNodeFlags : uint16_t {
  kSvoLeaf = 1u << 0,         // level == depth (a finest voxel)
  kSvoFrontLit = 1u << 1,     // front exitance came from samples in this subtree (not filled from a parent)
  kSvoBackLit = 1u << 2,      // same for the back side
  kSvoFrontFilled = 1u << 3,  // front exitance copied top-down from an ancestor
  kSvoBackFilled = 1u << 4,
};

// Octant index of a child: bit 0 = +x half, bit 1 = +y half, bit 2 = +z half.
struct SvoNode {
  uint32_t first_child = 0;        // index of the child with the lowest octant; 0 when child_mask == 0
  uint32_t parent = kSvoNoParent;  // kSvoNoParent for the root
  uint8_t child_mask = 0;          // bit i set: octant i has a child
  uint8_t level = 0;               // 0 = root (the whole cube), depth = leaves
  uint16_t flags = 0;              // SvoNodeFlags
  uint32_t normal_oct = 0;         // front-side normal, octahedral, two snorm16 (x low, y high)
  uint16_t exitance[6] = {0, 0, 0, 0, 0, 0};  // front RGB, back RGB: half floats times exitance_scale
};
static_assert(sizeof(SvoNode) == 28, "svo.bin node record is 28 bytes");

struct SparseVoxelOctree {
  std::array<float, 3> origin{0, 0, 0};  // minimum corner of the cube
  float size = 0;                        // cube edge length; leaf edge = size / 2^depth
  uint32_t depth = 0;                    // leaf level; resolution per axis = 2^depth
  float exitance_scale = 1;              // exitance = half_to_float(node.exitance[i]) * exitance_scale
  std::vector<SvoNode> nodes;            // nodes[0] = root; breadth-first
  std::vector<uint32_t> level_begin;     // depth + 2 entries: level l = [level_begin[l], level_begin[l+1])

  float voxel_size(uint32_t level) const { return size / float(1u << level); }
  uint32_t resolution() const { return 1u << depth; }
};

// Octahedral encoding of a unit vector into two snorm16 (Cigolle et al. 2014).
inline uint32_t encode_octahedral_normal(std::array<float, 3> n) {
  const float l1 = std::fabs(n[0]) + std::fabs(n[1]) + std::fabs(n[2]);
  if (!(l1 > 0)) return 0;
  float x = n[0] / l1, y = n[1] / l1;
  if (n[2] < 0) {
    const float ox = (1.0f - std::fabs(y)) * (x >= 0 ? 1.0f : -1.0f);
    const float oy = (1.0f - std::fabs(x)) * (y >= 0 ? 1.0f : -1.0f);
    x = ox;
    y = oy;
  }
  auto snorm = [](float v) {
    const float c = v < -1.0f ? -1.0f : (v > 1.0f ? 1.0f : v);
    return uint32_t(uint16_t(int16_t(std::lround(c * 32767.0f))));
  };
  return snorm(x) | (snorm(y) << 16);
}

inline std::array<float, 3> decode_octahedral_normal(uint32_t packed) {
  const float x0 = float(int16_t(uint16_t(packed & 0xFFFFu))) / 32767.0f;
  const float y0 = float(int16_t(uint16_t(packed >> 16))) / 32767.0f;
  float x = x0, y = y0;
  const float z = 1.0f - std::fabs(x0) - std::fabs(y0);
  if (z < 0) {
    x = (1.0f - std::fabs(y0)) * (x0 >= 0 ? 1.0f : -1.0f);
    y = (1.0f - std::fabs(x0)) * (y0 >= 0 ? 1.0f : -1.0f);
  }
  const float len = std::sqrt(x * x + y * y + z * z);
  if (!(len > 0)) return {0, 0, 1};
  return {x / len, y / len, z / len};
}

// The deepest node at or above `max_level` whose cube contains `p`; kSvoNoParent when p is outside
// the cube or the octree is empty. Descends from the root: O(depth), never reads out of bounds for
// a validated octree.
inline uint32_t svo_find_node(const SparseVoxelOctree& svo, std::array<float, 3> p, uint32_t max_level) {
  if (svo.nodes.empty() || !(svo.size > 0)) return kSvoNoParent;
  float local[3];
  for (int a = 0; a < 3; ++a) {
    local[a] = (p[a] - svo.origin[a]) / svo.size;
    if (!(local[a] >= 0.0f && local[a] <= 1.0f)) return kSvoNoParent;
  }
  const uint32_t levels = max_level < svo.depth ? max_level : svo.depth;
  uint32_t node = 0;
  for (uint32_t level = 0; level < levels; ++level) {
    const SvoNode& n = svo.nodes[node];
    const float cells = float(2u << level);  // cells per axis at level + 1
    uint32_t octant = 0;
    for (int a = 0; a < 3; ++a) {
      uint32_t cell = uint32_t(local[a] * cells);
      if (cell >= uint32_t(cells)) cell = uint32_t(cells) - 1;
      octant |= (cell & 1u) << a;
    }
    if (!(n.child_mask & (1u << octant))) break;
    node = n.first_child + uint32_t(std::popcount(uint32_t(n.child_mask & ((1u << octant) - 1u))));
  }
  return node;
}

// Exitance of one side (0 = front, 1 = back) of a node, RGB.
inline std::array<float, 3> svo_node_exitance(const SparseVoxelOctree& svo, uint32_t node, int side) {
  const SvoNode& n = svo.nodes[node];
  return {half_to_float(n.exitance[side * 3 + 0]) * svo.exitance_scale,
          half_to_float(n.exitance[side * 3 + 1]) * svo.exitance_scale,
          half_to_float(n.exitance[side * 3 + 2]) * svo.exitance_scale};
}

}  // namespace exitance::formats
