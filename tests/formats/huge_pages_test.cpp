// The huge-page helpers are only storage advice: what a vector holds after them is what resize,
// reserve and a copy would have left.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

#include "exitance/formats/huge_pages.h"

namespace exitance::formats {
namespace {

TEST(HugePages, ResizeKeepsTheElementsAndAddsZeros) {
  std::vector<uint32_t> values{7, 8, 9};
  resize_in_huge_pages(values, size_t(3) << 20);  // 12 MiB: whole 2 MiB pages inside
  ASSERT_EQ(values.size(), size_t(3) << 20);
  EXPECT_EQ(values[0], 7u);
  EXPECT_EQ(values[1], 8u);
  EXPECT_EQ(values[2], 9u);
  EXPECT_EQ(std::accumulate(values.begin() + 3, values.end(), uint64_t(0)), 0u);
  resize_in_huge_pages(values, 2);  // shrinking is a plain resize
  EXPECT_EQ(values, (std::vector<uint32_t>{7, 8}));
}

TEST(HugePages, ReserveKeepsTheElements) {
  std::vector<double> values{1.5, -2.5};
  reserve_in_huge_pages(values, size_t(1) << 20);
  EXPECT_GE(values.capacity(), size_t(1) << 20);
  EXPECT_EQ(values, (std::vector<double>{1.5, -2.5}));
  values.push_back(3.5);
  EXPECT_EQ(values.size(), 3u);
}

TEST(HugePages, CopyEqualsItsSource) {
  std::vector<float> source(size_t(1) << 21);
  std::iota(source.begin(), source.end(), 0.25f);
  EXPECT_EQ(copy_in_huge_pages(source), source);
  EXPECT_TRUE(copy_in_huge_pages(std::vector<float>{}).empty());
}

TEST(HugePages, AdviceOnMemoryWithoutAWholePageChangesNothing) {
  std::vector<uint8_t> small(100, 3);
  advise_huge_pages(small.data(), small.size());
  advise_huge_pages(nullptr, 0);
  EXPECT_EQ(small, std::vector<uint8_t>(100, 3));
}

}  // namespace
}  // namespace exitance::formats
