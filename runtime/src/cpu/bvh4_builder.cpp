#include "exitance/runtime/cpu/bvh4_builder.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "exitance/runtime/embree_device.h"

namespace exitance {
namespace {

// Temporary tree made by Embree's callbacks (memory from rtcThreadLocalAlloc, freed with the RTCBVH).
struct BuildNode {
  bool leaf = false;
  uint32_t count = 0;      // children (inner) or triangles (leaf)
  BuildNode* children[4] = {};
  RTCBounds bounds[4] = {};
  uint32_t triangles[kBvhMaxLeafTriangles] = {};
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int child_count, void*) {
  void* memory = rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16);
  BuildNode* node = new (memory) BuildNode;
  node->count = child_count;
  return node;
}

void set_node_children(void* node_ptr, void** children, unsigned int child_count, void*) {
  BuildNode* node = static_cast<BuildNode*>(node_ptr);
  for (unsigned i = 0; i < child_count; ++i) node->children[i] = static_cast<BuildNode*>(children[i]);
  node->count = child_count;
}

void set_node_bounds(void* node_ptr, const RTCBounds** bounds, unsigned int child_count, void*) {
  BuildNode* node = static_cast<BuildNode*>(node_ptr);
  for (unsigned i = 0; i < child_count; ++i) node->bounds[i] = *bounds[i];
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* primitives, size_t count, void*) {
  void* memory = rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16);
  BuildNode* node = new (memory) BuildNode;
  node->leaf = true;
  node->count = uint32_t(count);
  for (size_t i = 0; i < count; ++i) node->triangles[i] = primitives[i].primID;
  return node;
}

struct Flattener {
  Bvh4& out;

  uint32_t emit_leaf(const BuildNode* leaf) {
    const uint32_t first = uint32_t(out.leaf_triangles.size());
    if (first >= (1u << 29)) throw std::runtime_error("BVH: too many triangles for the leaf encoding");
    for (uint32_t i = 0; i < leaf->count; ++i) out.leaf_triangles.push_back(leaf->triangles[i]);
    return kBvhLeafBit | (first << 2) | (leaf->count - 1);
  }

  // Returns the stack entries that traversal below `node` can need.
  uint32_t emit_inner(const BuildNode* node, uint32_t index, uint32_t depth) {
    out.depth = std::max(out.depth, depth);
    uint32_t below = 0;
    for (uint32_t i = 0; i < 4; ++i) {
      Bvh4Node& n = out.nodes[index];
      if (i >= node->count) {
        n.child[i] = kBvhEmptyChild;
        n.lo_x[i] = n.lo_y[i] = n.lo_z[i] = 1.0f;  // empty box; the child word marks it anyway
        n.hi_x[i] = n.hi_y[i] = n.hi_z[i] = -1.0f;
        continue;
      }
      const RTCBounds& b = node->bounds[i];
      n.lo_x[i] = b.lower_x, n.lo_y[i] = b.lower_y, n.lo_z[i] = b.lower_z;
      n.hi_x[i] = b.upper_x, n.hi_y[i] = b.upper_y, n.hi_z[i] = b.upper_z;
      const BuildNode* c = node->children[i];
      if (c->leaf) {
        out.nodes[index].child[i] = emit_leaf(c);
      } else {
        const uint32_t child_index = uint32_t(out.nodes.size());
        out.nodes.emplace_back();
        out.nodes[index].child[i] = child_index;
        below = std::max(below, emit_inner(c, child_index, depth + 1));
      }
    }
    // Visiting a node pushes up to count entries and pops one.
    return below + node->count;
  }
};

}  // namespace

Bvh4 build_bvh4(const Scene& scene) {
  Bvh4 bvh;
  const size_t triangle_count = scene.triangle_count();
  std::vector<RTCBuildPrimitive> primitives;
  primitives.reserve(triangle_count);
  for (size_t t = 0; t < triangle_count; ++t) {
    const Vec3* p = &scene.positions[t * 3];
    const Vec3 lo = min(min(p[0], p[1]), p[2]), hi = max(max(p[0], p[1]), p[2]);
    if (!is_finite(lo) || !is_finite(hi)) continue;  // never hit by Embree either
    RTCBuildPrimitive prim{};
    prim.lower_x = lo.x, prim.lower_y = lo.y, prim.lower_z = lo.z, prim.geomID = 0;
    prim.upper_x = hi.x, prim.upper_y = hi.y, prim.upper_z = hi.z, prim.primID = uint32_t(t);
    primitives.push_back(prim);
  }
  bvh.nodes.emplace_back();
  if (primitives.empty()) {
    for (int i = 0; i < 4; ++i) {
      bvh.nodes[0].child[i] = kBvhEmptyChild;
      bvh.nodes[0].lo_x[i] = bvh.nodes[0].lo_y[i] = bvh.nodes[0].lo_z[i] = 1.0f;
      bvh.nodes[0].hi_x[i] = bvh.nodes[0].hi_y[i] = bvh.nodes[0].hi_z[i] = -1.0f;
    }
    return bvh;
  }

  RTCDevice device = new_embree_device();
  RTCBVH handle = rtcNewBVH(device);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildFlags = RTC_BUILD_FLAG_NONE;
  args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;  // SAH binning; HIGH would need a splitPrimitive callback
  args.maxBranchingFactor = 4;
  args.maxDepth = 48;
  args.sahBlockSize = 1;
  args.minLeafSize = 1;
  args.maxLeafSize = kBvhMaxLeafTriangles;
  args.traversalCost = 1.0f;
  args.intersectionCost = 1.0f;
  args.bvh = handle;
  args.primitives = primitives.data();
  args.primitiveCount = primitives.size();
  args.primitiveArrayCapacity = primitives.size();
  args.createNode = create_node;
  args.setNodeChildren = set_node_children;
  args.setNodeBounds = set_node_bounds;
  args.createLeaf = create_leaf;
  args.splitPrimitive = nullptr;
  args.buildProgress = nullptr;
  args.userPtr = nullptr;
  BuildNode* root = static_cast<BuildNode*>(rtcBuildBVH(&args));
  if (!root || rtcGetDeviceError(device) != RTC_ERROR_NONE) {
    rtcReleaseBVH(handle);
    rtcReleaseDevice(device);
    throw std::runtime_error("Embree: rtcBuildBVH failed for the BVH4");
  }
  bvh.leaf_triangles.reserve(primitives.size());
  Flattener flattener{bvh};
  if (root->leaf) {
    // Wrap a single leaf into a root with one child.
    BuildNode wrapper;
    wrapper.count = 1;
    wrapper.children[0] = root;
    RTCBounds b{};
    b.lower_x = b.lower_y = b.lower_z = std::numeric_limits<float>::max();
    b.upper_x = b.upper_y = b.upper_z = -std::numeric_limits<float>::max();
    for (const RTCBuildPrimitive& p : primitives) {
      b.lower_x = std::min(b.lower_x, p.lower_x), b.lower_y = std::min(b.lower_y, p.lower_y);
      b.lower_z = std::min(b.lower_z, p.lower_z), b.upper_x = std::max(b.upper_x, p.upper_x);
      b.upper_y = std::max(b.upper_y, p.upper_y), b.upper_z = std::max(b.upper_z, p.upper_z);
    }
    wrapper.bounds[0] = b;
    bvh.stack_entries = flattener.emit_inner(&wrapper, 0, 1);
  } else {
    bvh.stack_entries = flattener.emit_inner(root, 0, 1);
  }
  rtcReleaseBVH(handle);
  rtcReleaseDevice(device);
  return bvh;
}

}  // namespace exitance
