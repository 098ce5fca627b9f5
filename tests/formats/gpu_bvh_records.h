// The GPU BVH (runtime/src/vulkan/gpu_bvh.h) as scene.bin records and back. The node layouts are
// the same 112 bytes; a leaf slot is stored as its scene triangle index (word 3 of the slot's
// vertex copy) and the vertex copies are rebuilt from the scene's positions. The lead wires this
// into the Vulkan backend; the tests use it to store the real builder's output.
#pragma once
#include <bit>
#include <cstring>

#include "exitance/formats/scene_file.h"
#include "gpu_bvh.h"

namespace exitance::test {

static_assert(sizeof(vulkan::GpuBvhNode) == sizeof(formats::BvhNodeRecord));
static_assert(vulkan::kEmptyChild == formats::kSceneBvhEmptyChild && vulkan::kLeafBit == formats::kSceneBvhLeafBit);

inline formats::SceneBvh scene_bvh_from_gpu(const vulkan::GpuBvh& gpu) {
  formats::SceneBvh out;
  out.nodes.resize(gpu.nodes.size());
  for (size_t i = 0; i < gpu.nodes.size(); ++i) {
    const vulkan::GpuBvhNode& n = gpu.nodes[i];
    formats::BvhNodeRecord& r = out.nodes[i];
    for (int c = 0; c < 4; ++c) {
      r.lo_x[c] = n.lo_x[c], r.hi_x[c] = n.hi_x[c], r.lo_y[c] = n.lo_y[c];
      r.hi_y[c] = n.hi_y[c], r.lo_z[c] = n.lo_z[c], r.hi_z[c] = n.hi_z[c];
      r.child[c] = n.child[c];
    }
  }
  for (const std::array<float, 12>& slot : gpu.triangles)
    out.leaf_triangles.push_back(std::bit_cast<uint32_t>(slot[3]));
  out.stack_entries = gpu.stack_entries;
  out.depth = gpu.depth;
  return out;
}

inline vulkan::GpuBvh gpu_bvh_from_records(const formats::SceneBvh& records, const Scene& scene) {
  vulkan::GpuBvh gpu;
  gpu.nodes.resize(records.nodes.size());
  for (size_t i = 0; i < records.nodes.size(); ++i) {
    const formats::BvhNodeRecord& r = records.nodes[i];
    vulkan::GpuBvhNode& n = gpu.nodes[i];
    for (int c = 0; c < 4; ++c) {
      n.lo_x[c] = r.lo_x[c], n.hi_x[c] = r.hi_x[c], n.lo_y[c] = r.lo_y[c];
      n.hi_y[c] = r.hi_y[c], n.lo_z[c] = r.lo_z[c], n.hi_z[c] = r.hi_z[c];
      n.child[c] = r.child[c];
    }
  }
  for (uint32_t t : records.leaf_triangles) {
    std::array<float, 12> v{};
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = scene.positions[size_t(t) * 3 + size_t(k)];
      v[size_t(4 * k)] = p.x, v[size_t(4 * k + 1)] = p.y, v[size_t(4 * k + 2)] = p.z;
    }
    std::memcpy(&v[3], &t, 4);
    gpu.triangles.push_back(v);
  }
  gpu.stack_entries = records.stack_entries;
  gpu.depth = records.depth;
  return gpu;
}

}  // namespace exitance::test
