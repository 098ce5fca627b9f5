// bake under mpirun (issue 15): the split of items over ranks by counted cost (core/work_share.h).
#include <gtest/gtest.h>

#include <numeric>

#include "exitance/runtime/core/work_share.h"

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

}  // namespace
}  // namespace exitance
