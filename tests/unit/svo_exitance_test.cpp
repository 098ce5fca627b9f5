// SvoExitanceCache on a hand-built octree: side selection by the voxel normal, weighted means,
// the bottom-up filter with side flips, the top-down fill, refresh semantics (replace vs moving
// average) and half encoding with the per-file scale.
#include <gtest/gtest.h>

#include "exitance/runtime/svo_exitance.h"

namespace exitance {
namespace {

using formats::SparseVoxelOctree;
using formats::SvoNode;

// Unit cube at the origin, depth 1: the root and two leaves, octant 0 (x < 0.5) with normal +y and
// octant 1 (x >= 0.5) with normal -y, i.e. opposite to the root's +y.
SparseVoxelOctree two_leaf_octree() {
  SparseVoxelOctree svo;
  svo.origin = {0, 0, 0};
  svo.size = 1;
  svo.depth = 1;
  svo.nodes.resize(3);
  svo.nodes[0].first_child = 1;
  svo.nodes[0].child_mask = 0b11;
  svo.nodes[0].normal_oct = formats::encode_octahedral_normal({0, 1, 0});
  for (uint32_t i = 1; i < 3; ++i) {
    svo.nodes[i].parent = 0;
    svo.nodes[i].level = 1;
    svo.nodes[i].flags = formats::kSvoLeaf;
  }
  svo.nodes[1].normal_oct = formats::encode_octahedral_normal({0, 1, 0});
  svo.nodes[2].normal_oct = formats::encode_octahedral_normal({0, -1, 0});
  svo.level_begin = {0, 1, 3};
  return svo;
}

Vec3 stored(const SparseVoxelOctree& svo, uint32_t node, int side) {
  const auto v = formats::svo_node_exitance(svo, node, side);
  return {v[0], v[1], v[2]};
}

void expect_vec(Vec3 actual, Vec3 expected, float tolerance) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(actual[c], expected[c], tolerance * std::max(1.0f, std::fabs(expected[c])));
}

TEST(SvoExitance, SidesFilterAndFill) {
  SparseVoxelOctree svo = two_leaf_octree();
  SvoExitanceCache cache(svo);
  cache.deposit({{0.2f, 0.2f, 0.2f}, {0, 1, 0}, {1, 2, 3}, 1});   // leaf 1 front
  cache.deposit({{0.3f, 0.1f, 0.4f}, {0, 1, 0}, {3, 2, 1}, 1});   // leaf 1 front
  cache.deposit({{0.3f, 0.1f, 0.4f}, {0, -1, 0}, {10, 0, 0}, 1}); // leaf 1 back
  cache.deposit({{0.7f, 0.2f, 0.2f}, {0, 1, 0}, {4, 4, 4}, 2});   // leaf 2 back (its normal is -y)
  cache.deposit({{1.5f, 0.5f, 0.5f}, {0, 1, 0}, {9, 9, 9}, 1});   // outside the cube: dropped
  cache.publish();
  EXPECT_EQ(cache.dropped_samples(), 1u);
  cache.store_into(svo);
  const float half_precision = 1.0f / 1024.0f;
  expect_vec(stored(svo, 1, 0), {2, 2, 2}, half_precision);
  expect_vec(stored(svo, 1, 1), {10, 0, 0}, half_precision);
  expect_vec(stored(svo, 2, 1), {4, 4, 4}, half_precision);
  // Root front = leaf 1 front (weight 2) and leaf 2 back flipped (weight 2): mean (3, 3, 3).
  expect_vec(stored(svo, 0, 0), {3, 3, 3}, half_precision);
  expect_vec(stored(svo, 0, 1), {10, 0, 0}, half_precision);
  // Leaf 2's front had no samples: filled from the root's back side (flipped normal).
  expect_vec(stored(svo, 2, 0), {10, 0, 0}, half_precision);
  EXPECT_TRUE(svo.nodes[2].flags & formats::kSvoFrontFilled);
  EXPECT_TRUE(svo.nodes[2].flags & formats::kSvoBackLit);
  EXPECT_TRUE(svo.nodes[1].flags & formats::kSvoFrontLit);
  EXPECT_FALSE(svo.nodes[0].flags & formats::kSvoLeaf);
}

TEST(SvoExitance, RefreshReplacesOrBlendsInsteadOfSummingForever) {
  SparseVoxelOctree svo = two_leaf_octree();
  SvoExitanceCache cache(svo);
  cache.deposit({{0.2f, 0.2f, 0.2f}, {0, 1, 0}, {8, 8, 8}, 1});
  cache.publish();
  // The light changed: the next refresh sees 2 instead of 8.
  cache.deposit({{0.2f, 0.2f, 0.2f}, {0, 1, 0}, {2, 2, 2}, 1});
  cache.publish(1.0f);
  expect_vec(cache.published(1, 0), {2, 2, 2}, 1e-6f);
  cache.deposit({{0.2f, 0.2f, 0.2f}, {0, 1, 0}, {4, 4, 4}, 1});
  cache.publish(0.25f);
  expect_vec(cache.published(1, 0), {2.5f, 2.5f, 2.5f}, 1e-6f);
  // A refresh without samples for a side keeps its value.
  cache.publish(1.0f);
  expect_vec(cache.published(1, 0), {2.5f, 2.5f, 2.5f}, 1e-6f);
  EXPECT_THROW(cache.publish(0.0f), std::invalid_argument);
}

TEST(SvoExitance, BrightValuesKeepPrecisionThroughTheScale) {
  SparseVoxelOctree svo = two_leaf_octree();
  SvoExitanceCache cache(svo);
  cache.deposit({{0.2f, 0.2f, 0.2f}, {0, 1, 0}, {1e7f, 3e6f, 1.0f}, 1});
  cache.publish();
  cache.store_into(svo);
  EXPECT_GT(svo.exitance_scale, 1.0f);
  const Vec3 v = stored(svo, 1, 0);
  EXPECT_NEAR(v.x, 1e7f, 1e7f / 1024);
  EXPECT_NEAR(v.y, 3e6f, 3e6f / 1024);
  for (const auto& node : svo.nodes)
    for (uint16_t h : node.exitance) EXPECT_TRUE(std::isfinite(formats::half_to_float(h)));
}

}  // namespace
}  // namespace exitance
