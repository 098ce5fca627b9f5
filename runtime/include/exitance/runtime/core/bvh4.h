// The 4-wide BVH every backend can traverse (shaders/include/bvh.glsl on the GPU): built by the
// offline stage (Embree's rtcBuildBVH, runtime/src/cpu/bvh4_builder.cpp) or read from scene.bin,
// never rebuilt by the runtime. Flattened depth-first: nodes[0] is the root.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

namespace exitance {

constexpr uint32_t kBvhEmptyChild = 0xFFFFFFFFu;
constexpr uint32_t kBvhLeafBit = 0x80000000u;  // child word of a leaf: bit 31 | first slot << 2 | count - 1
constexpr uint32_t kBvhMaxLeafTriangles = 4;

// 7 x vec4 (112 bytes): lo.x[4], hi.x[4], lo.y[4], hi.y[4], lo.z[4], hi.z[4], child[4] (bits).
struct Bvh4Node {
  float lo_x[4], hi_x[4], lo_y[4], hi_y[4], lo_z[4], hi_z[4];
  uint32_t child[4];
};
static_assert(sizeof(Bvh4Node) == 112);

struct Bvh4 {
  std::vector<Bvh4Node> nodes;
  std::vector<uint32_t> leaf_triangles;  // per leaf slot: the scene triangle it holds (a split triangle in several)
  uint32_t stack_entries = 1;            // traversal stack bound (shaders' kStackSize)
  uint32_t depth = 0;
};

}  // namespace exitance
