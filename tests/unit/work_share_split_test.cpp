// bake under mpirun (issue 15): the split of items over ranks by counted cost (CPU backend) and in
// interleaved blocks (Vulkan backend), and the gather of an interleaved split onto rank 0 (core/work_share.h).
#include <gtest/gtest.h>

#include <cstring>
#include <numeric>

#include "exitance/runtime/core/work_share.h"
#include "support/sequential_ranks.h"

namespace exitance {
namespace {

TEST(SplitByCost, WithoutCostsSplitsEvenly) {
  EXPECT_EQ(split_by_cost(10, {}, 2), (std::vector<size_t>{0, 5, 10}));
  EXPECT_EQ(split_by_cost(10, {}, 3), (std::vector<size_t>{0, 3, 6, 10}));
  EXPECT_EQ(split_by_cost(10, {}, 1), (std::vector<size_t>{0, 10}));
}

TEST(SplitByCost, FollowsTheCounts) {
  // Item 0 costs as much as the other nine together (+1 each): rank 0 gets it alone.
  std::vector<uint64_t> cost(10, 9);
  cost[0] = 99;
  EXPECT_EQ(split_by_cost(10, cost, 2), (std::vector<size_t>{0, 1, 10}));
  // Costs 0 still count 1 each: an all-zero pass splits evenly.
  EXPECT_EQ(split_by_cost(10, std::vector<uint64_t>(10, 0), 2), (std::vector<size_t>{0, 5, 10}));
}

TEST(SplitByCost, EveryRankGetsAboutItsShare) {
  std::vector<uint64_t> cost(1000);
  for (size_t i = 0; i < cost.size(); ++i) cost[i] = (i * 7919) % 97;  // uneven, deterministic
  const int ranks = 4;
  const std::vector<size_t> b = split_by_cost(cost.size(), cost, ranks);
  ASSERT_EQ(b.size(), size_t(ranks) + 1);
  EXPECT_EQ(b.front(), 0u);
  EXPECT_EQ(b.back(), cost.size());
  const double total = std::accumulate(cost.begin(), cost.end(), 0.0) + double(cost.size());
  for (int r = 0; r < ranks; ++r) {
    ASSERT_LE(b[size_t(r)], b[size_t(r) + 1]);
    double share = 0;
    for (size_t i = b[size_t(r)]; i < b[size_t(r) + 1]; ++i) share += double(cost[i]) + 1;
    // Contiguous ranges: off the ideal share by at most one item's cost (97 + 1).
    EXPECT_NEAR(share, total / ranks, 98.0) << "rank " << r;
  }
}

TEST(SplitByCost, MoreRanksThanItemsLeavesSomeEmpty) {
  const std::vector<size_t> b = split_by_cost(2, {5, 5}, 4);
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(b.front(), 0u);
  EXPECT_EQ(b.back(), 2u);
  for (size_t r = 0; r + 1 < b.size(); ++r) EXPECT_LE(b[r], b[r + 1]);
}

TEST(InterleavedSplit, EveryItemHasOneRankAndRanksGetBlocksInTurn) {
  InterleavedSplit split;
  split.items = 10;
  split.ranks = 3;
  split.block = 2;
  EXPECT_EQ(split.items_of(0), (std::vector<uint32_t>{0, 1, 6, 7}));
  EXPECT_EQ(split.items_of(1), (std::vector<uint32_t>{2, 3, 8, 9}));
  EXPECT_EQ(split.items_of(2), (std::vector<uint32_t>{4, 5}));
  EXPECT_EQ(split.runs_of(1), (std::vector<std::pair<size_t, size_t>>{{2, 4}, {8, 10}}));
  EXPECT_EQ(split.runs_of(2), (std::vector<std::pair<size_t, size_t>>{{4, 6}}));
  EXPECT_EQ(split.count_of(0) + split.count_of(1) + split.count_of(2), 10u);
  EXPECT_EQ(split.count_of(2), 2u);
  split.ranks = 1;
  EXPECT_EQ(split.items_of(0).size(), 10u);
  split.items = 0;
  split.ranks = 2;
  EXPECT_TRUE(split.items_of(1).empty());
}

TEST(InterleavedSplit, GatherToRootGivesRankZeroEveryItem) {
  InterleavedSplit split;
  split.items = 1000;  // not a multiple of the blocks: the last run is short
  split.ranks = 3;
  split.block = 64;
  constexpr size_t kValues = 3;
  auto value = [](size_t item, size_t c) { return double(item) * 10 + double(c); };
  testing::SequentialRanks::World world;
  // Ranks 2 and 1 send their items packed, run after run.
  for (int r = 2; r >= 1; --r) {
    std::vector<double> packed;
    for (uint32_t i : split.items_of(r))
      for (size_t c = 0; c < kValues; ++c) packed.push_back(value(i, c));
    ASSERT_EQ(packed.size(), split.count_of(r) * kValues);
    testing::SequentialRanks share(world, r, 3);
    gather_interleaved_to_root(share, packed.data(), kValues, split);
  }
  // Rank 0 holds the whole array with its own items in place.
  std::vector<double> whole(split.items * kValues, -1.0);
  for (uint32_t i : split.items_of(0))
    for (size_t c = 0; c < kValues; ++c) whole[i * kValues + c] = value(i, c);
  testing::SequentialRanks root(world, 0, 3);
  gather_interleaved_to_root(root, whole.data(), kValues, split);
  for (size_t i = 0; i < split.items; ++i)
    for (size_t c = 0; c < kValues; ++c) ASSERT_EQ(whole[i * kValues + c], value(i, c)) << "item " << i;
}

}  // namespace
}  // namespace exitance
