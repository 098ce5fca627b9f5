#include "exitance/runtime/cpu/bvh4_builder.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "exitance/runtime/embree_device.h"
#include "exitance/runtime/float_rounding.h"

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

struct DoubleBox {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  void grow(const double p[3]) {
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
};

// The part of the triangle on each side of the plane p[dimension] = position, as float boxes that
// contain it (edge crossings computed in double and rounded outward), clipped to the fragment's
// current bounds: a fragment already split elsewhere only keeps what lies inside its box.
void split_triangle(const RTCBuildPrimitive* primitive, unsigned int dimension, float position, RTCBounds* left_bounds,
                    RTCBounds* right_bounds, void* user) {
  const Scene& scene = *static_cast<const Scene*>(user);
  const Vec3* p = &scene.positions[size_t(primitive->primID) * 3];
  double v[3][3];
  for (int i = 0; i < 3; ++i) v[i][0] = p[i].x, v[i][1] = p[i].y, v[i][2] = p[i].z;
  const double plane = position;
  DoubleBox left, right;
  for (int i = 0; i < 3; ++i) {
    const double* a = v[i];
    const double* b = v[(i + 1) % 3];
    if (a[dimension] <= plane) left.grow(a);
    if (a[dimension] >= plane) right.grow(a);
    if ((a[dimension] < plane && b[dimension] > plane) || (a[dimension] > plane && b[dimension] < plane)) {
      const double t = (plane - a[dimension]) / (b[dimension] - a[dimension]);
      double crossing[3];
      for (int k = 0; k < 3; ++k) crossing[k] = a[k] + t * (b[k] - a[k]);
      crossing[dimension] = plane;
      left.grow(crossing);
      right.grow(crossing);
    }
  }
  const float fragment_lo[3] = {primitive->lower_x, primitive->lower_y, primitive->lower_z};
  const float fragment_hi[3] = {primitive->upper_x, primitive->upper_y, primitive->upper_z};
  auto write = [&](const DoubleBox& box, RTCBounds* out) {
    float lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      // One more float step outward: the crossings' double arithmetic rounds too.
      lo[k] = std::max(std::nextafter(float_at_or_below(box.lo[k]), -INFINITY), fragment_lo[k]);
      hi[k] = std::min(std::nextafter(float_at_or_above(box.hi[k]), INFINITY), fragment_hi[k]);
      // The triangle's part on this side can miss the fragment's box (the box is not tight around
      // the fragment): a point box keeps the reference valid; it holds nothing a ray can miss.
      if (lo[k] > hi[k]) lo[k] = hi[k] = std::clamp(lo[k], fragment_lo[k], fragment_hi[k]);
    }
    out->lower_x = lo[0], out->lower_y = lo[1], out->lower_z = lo[2], out->align0 = 0;
    out->upper_x = hi[0], out->upper_y = hi[1], out->upper_z = hi[2], out->align1 = 0;
  };
  write(left, left_bounds);
  write(right, right_bounds);
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

  // Spatial splits (Stich et al. 2009, Embree's HIGH quality): a large triangle's reference may be
  // split into fragments whose boxes overlap less, so a slot list may name a triangle more than once.
  // Embree writes the fragments into the array's spare capacity and stops splitting once it is
  // full: with room for one more reference per triangle, the leaf slots stay within twice the
  // triangles (scene.bin's rule). Measured on the H200: the open
  // city +10 % rays/s (1.78 -> 1.95 G end to end, 13 % more slots), the building unchanged (0.05 %
  // more slots: axis-aligned walls are already tight): bench/results/open-city-gpu.md.
  const size_t primitive_count = primitives.size();
  primitives.resize(primitive_count * 2);
  RTCDevice device = new_embree_device();
  RTCBVH handle = rtcNewBVH(device);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildFlags = RTC_BUILD_FLAG_NONE;
  args.buildQuality = RTC_BUILD_QUALITY_HIGH;
  args.maxBranchingFactor = 4;
  args.maxDepth = 48;
  args.sahBlockSize = 1;
  args.minLeafSize = 1;
  args.maxLeafSize = kBvhMaxLeafTriangles;
  args.traversalCost = 1.0f;
  args.intersectionCost = 1.0f;  // 0.5 cost the building 2.4 %, 2.0 changed nothing (H200)
  args.bvh = handle;
  args.primitives = primitives.data();
  args.primitiveCount = primitive_count;
  args.primitiveArrayCapacity = primitives.size();
  args.createNode = create_node;
  args.setNodeChildren = set_node_children;
  args.setNodeBounds = set_node_bounds;
  args.createLeaf = create_leaf;
  args.splitPrimitive = split_triangle;
  args.buildProgress = nullptr;
  args.userPtr = const_cast<Scene*>(&scene);
  BuildNode* root = static_cast<BuildNode*>(rtcBuildBVH(&args));
  if (!root || rtcGetDeviceError(device) != RTC_ERROR_NONE) {
    rtcReleaseBVH(handle);
    rtcReleaseDevice(device);
    throw std::runtime_error("Embree: rtcBuildBVH failed for the BVH4");
  }
  bvh.leaf_triangles.reserve(primitive_count);
  Flattener flattener{bvh};
  if (root->leaf) {
    // Wrap a single leaf into a root with one child.
    BuildNode wrapper;
    wrapper.count = 1;
    wrapper.children[0] = root;
    RTCBounds b{};
    b.lower_x = b.lower_y = b.lower_z = std::numeric_limits<float>::max();
    b.upper_x = b.upper_y = b.upper_z = -std::numeric_limits<float>::max();
    for (size_t i = 0; i < primitive_count; ++i) {
      const RTCBuildPrimitive& p = primitives[i];
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
