// A 4-wide BVH for GPU traversal (shaders/include/bvh.glsl), built by Embree's rtcBuildBVH with
// our own node callbacks and flattened depth-first.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "exitance/runtime/scene.h"

namespace exitance::vulkan {

constexpr uint32_t kEmptyChild = 0xFFFFFFFFu;
constexpr uint32_t kLeafBit = 0x80000000u;
constexpr uint32_t kMaxLeafTriangles = 4;

// 7 x vec4: lo.x[4], hi.x[4], lo.y[4], hi.y[4], lo.z[4], hi.z[4], child[4] (bits).
struct GpuBvhNode {
  float lo_x[4], hi_x[4], lo_y[4], hi_y[4], lo_z[4], hi_z[4];
  uint32_t child[4];
};
static_assert(sizeof(GpuBvhNode) == 112);

struct GpuBvh {
  std::vector<GpuBvhNode> nodes;          // nodes[0] is the root (an inner node, possibly with empty children)
  std::vector<std::array<float, 12>> triangles;  // per leaf slot: v0.xyz|scene triangle bits, v1.xyz|0, v2.xyz|0
  uint32_t stack_entries = 1;             // traversal stack bound (shaders' kStackSize)
  uint32_t depth = 0;
};

GpuBvh build_gpu_bvh(const Scene& scene);

}  // namespace exitance::vulkan
