// The BVH4 builder with spatial splits (runtime/src/cpu/bvh4_builder.cpp): long diagonal slivers,
// which Embree's spatial-split SAH cuts into fragments, must still be found by every ray that
// meets them, whichever leaf holds the fragment it meets.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "exitance/runtime/core/bvh4_refit.h"
#include "exitance/runtime/core/bvh4_walk.h"
#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/scene.h"

namespace exitance {
namespace {

// Slivers across the unit cube in random directions, plus small triangles: a scene where object
// splits leave large overlapping boxes, so the builder splits references.
Scene slivers(uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Scene scene;
  for (int i = 0; i < count; ++i) {
    const Vec3 a{u(rng), u(rng), u(rng)};
    const bool sliver = i % 2 == 0;
    const Vec3 b = sliver ? Vec3{u(rng), u(rng), u(rng)} : a + Vec3{u(rng), u(rng), u(rng)} * 0.05f;
    const Vec3 c = a + Vec3{u(rng), u(rng), u(rng)} * (sliver ? 0.02f : 0.05f);
    for (const Vec3& p : {a, b, c}) {
      scene.positions.push_back(p);
      scene.normals.push_back(Vec3{0, 0, 1});
      scene.uv0.push_back(Vec2{0, 0});
      scene.lightmap_uv.push_back(Vec2{0, 0});
    }
    scene.triangle_material.push_back(0);
    scene.triangle_instance.push_back(0);
  }
  scene.materials.emplace_back();
  return scene;
}

// Per triangle, the leaf boxes (child c of node n) that hold it.
struct LeafBox {
  double lo[3], hi[3];
};
std::vector<std::vector<LeafBox>> boxes_per_triangle(const Bvh4& bvh, size_t triangles) {
  std::vector<std::vector<LeafBox>> boxes(triangles);
  for (const Bvh4Node& n : bvh.nodes)
    for (int c = 0; c < 4; ++c) {
      const uint32_t word = n.child[c];
      if (word == kBvhEmptyChild || !(word & kBvhLeafBit)) continue;
      const uint32_t first = (word & ~kBvhLeafBit) >> 2, count = (word & 3u) + 1;
      const LeafBox box{{n.lo_x[c], n.lo_y[c], n.lo_z[c]}, {n.hi_x[c], n.hi_y[c], n.hi_z[c]}};
      for (uint32_t s = first; s < first + count; ++s) boxes[bvh.leaf_triangles[s]].push_back(box);
    }
  return boxes;
}

TEST(Bvh4SpatialSplits, SliversAreSplitWithinTheSlotBound) {
  const Scene scene = slivers(1, 4000);
  const Bvh4 bvh = build_bvh4(scene);
  // Without a split this test would check nothing new.
  EXPECT_GT(bvh.leaf_triangles.size(), scene.triangle_count() * 11 / 10);
  EXPECT_LE(bvh.leaf_triangles.size(), scene.triangle_count() * 2);
  std::vector<int> slots(scene.triangle_count(), 0);
  for (uint32_t t : bvh.leaf_triangles) ++slots.at(t);
  for (size_t t = 0; t < slots.size(); ++t) EXPECT_GE(slots[t], 1) << "triangle " << t;
}

// Of 67 points per triangle (corners, edge points, interior), how many lie in no leaf box holding it.
size_t uncovered_points(const Scene& scene, const Bvh4& bvh) {
  const auto boxes = boxes_per_triangle(bvh, scene.triangle_count());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  size_t uncovered = 0;
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    const Vec3* p = &scene.positions[t * 3];
    for (int k = 0; k < 67; ++k) {
      double b1 = u(rng), b2 = u(rng);
      if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
      if (k < 3) b1 = k == 1, b2 = k == 2;           // the corners
      else if (k < 6) b2 = k == 3 ? 0 : 1 - b1;      // edge points
      if (k == 5) b1 = 0;
      const double q[3] = {p[0].x + b1 * (double(p[1].x) - p[0].x) + b2 * (double(p[2].x) - p[0].x),
                           p[0].y + b1 * (double(p[1].y) - p[0].y) + b2 * (double(p[2].y) - p[0].y),
                           p[0].z + b1 * (double(p[1].z) - p[0].z) + b2 * (double(p[2].z) - p[0].z)};
      bool inside = false;
      for (const LeafBox& box : boxes[t]) {
        bool in = true;
        for (int a = 0; a < 3; ++a) in = in && q[a] >= box.lo[a] && q[a] <= box.hi[a];
        inside = inside || in;
      }
      uncovered += inside ? 0 : 1;
    }
  }
  return uncovered;
}

// Every point of every triangle (corners, edge points, interior) lies in a leaf box holding it.
TEST(Bvh4SpatialSplits, LeafBoxesCoverEveryPointOfTheirTriangle) {
  const Scene scene = slivers(2, 3000);
  const Bvh4 bvh = build_bvh4(scene);
  EXPECT_EQ(uncovered_points(scene, bvh), 0u) << "of " << 67 * scene.triangle_count() << " points";
}

// A refit after half the triangles turned and moved (bvh4_refit.h): the moved triangles' fragments
// are carried with them, so every point of every triangle is still in a leaf box holding it, and the
// leaves stay about as tight as the built ones (a refit to whole-triangle bounds is compared).
TEST(Bvh4SpatialSplits, RefitCarriesTheFragmentsOfMovedTriangles) {
  Scene scene = slivers(4, 3000);
  const std::vector<Vec3> before = scene.positions;
  Bvh4 bvh = build_bvh4(scene);
  const float c = std::cos(0.4f), s = std::sin(0.4f);
  for (size_t t = 0; t < scene.triangle_count(); t += 2)
    for (size_t k = 0; k < 3; ++k) {
      Vec3& v = scene.positions[t * 3 + k];
      v = Vec3{c * v.x - s * v.y + 0.25f, s * v.x + c * v.y, v.z - 0.125f};
    }
  Bvh4 whole = bvh;
  refit_bvh4(whole, scene.positions);
  refit_bvh4(bvh, scene.positions, &before);
  EXPECT_EQ(uncovered_points(scene, bvh), 0u) << "of " << 67 * scene.triangle_count() << " points";
  // Summed leaf box areas: carrying the fragments keeps them well below the whole-triangle refit's.
  auto leaf_area = [](const Bvh4& b) {
    double area = 0;
    for (const Bvh4Node& n : b.nodes)
      for (int i = 0; i < 4; ++i)
        if (n.child[i] != kBvhEmptyChild && (n.child[i] & kBvhLeafBit)) {
          const double x = n.hi_x[i] - n.lo_x[i], y = n.hi_y[i] - n.lo_y[i], z = n.hi_z[i] - n.lo_z[i];
          area += 2 * (x * y + y * z + z * x);
        }
    return area;
  };
  EXPECT_LT(leaf_area(bvh), 0.8 * leaf_area(whole));
}

// The walk over the split tree finds the nearest hit a loop over all triangles finds (the same
// triangle test, so the same distance; which of two equally near triangles is not compared).
TEST(Bvh4SpatialSplits, ClosestHitsEqualABruteForceSearch) {
  const Scene scene = slivers(3, 2000);
  const Bvh4 bvh = build_bvh4(scene);
  auto corners = [&](uint32_t t, Vec3& p0, Vec3& p1, Vec3& p2) {
    p0 = scene.positions[t * 3], p1 = scene.positions[t * 3 + 1], p2 = scene.positions[t * 3 + 2];
  };
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  std::vector<uint32_t> stack;
  int hits = 0;
  for (int r = 0; r < 4000; ++r) {
    const Vec3 o{u(rng), u(rng), u(rng)};
    const Vec3 d = normalize(Vec3{u(rng), u(rng), u(rng)});
    const Bvh4WalkHit walk =
        bvh4_closest_hit(bvh.nodes.data(), bvh.nodes.size(), bvh.leaf_triangles.data(), corners, o, d, 1e30f, stack);
    double best = -1;
    for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
      Vec3 p0, p1, p2;
      corners(t, p0, p1, p2);
      const TriangleIntersection hit = intersect_triangle(o, d, p0, p1, p2);
      if (hit.distance > 0 && (best < 0 || hit.distance < best)) best = hit.distance;
    }
    ASSERT_EQ(walk.found, best > 0) << "ray " << r;
    if (best > 0) EXPECT_EQ(walk.distance, best) << "ray " << r;
    hits += best > 0;
  }
  EXPECT_GT(hits, 400);
}

bool same_bvh(const Bvh4& a, const Bvh4& b) {
  return a.nodes.size() == b.nodes.size() && a.leaf_triangles == b.leaf_triangles && a.depth == b.depth &&
         a.stack_entries == b.stack_entries &&
         std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(Bvh4Node)) == 0;
}

// scene.bin holds the tree, and bundles are compared byte for byte across runs and ranks.
TEST(Bvh4SpatialSplits, SameTreeOnEveryThreadCount) {
  const Scene scene = slivers(4, 20000);
  const Bvh4 reference = build_bvh4(scene);
  for (int threads : {1, 2, 3}) {
    tbb::task_arena arena(threads);
    Bvh4 again;
    arena.execute([&] { again = build_bvh4(scene); });
    EXPECT_TRUE(same_bvh(reference, again)) << threads << " threads";
  }
}

}  // namespace
}  // namespace exitance
