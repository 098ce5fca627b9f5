// path_sampler.h: the draws are uniform in both modes, and the Sobol mode stratifies an item's samples
// as a (0, m, 2)-net (its first 2^m 2-D points put exactly one point in every elementary interval of
// area 2^-m) while different items and dimensions stay independent.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "exitance/common/path_sampler.h"

namespace exitance {
namespace {

// Pearson chi-square of `count` against a uniform expectation; for k bins its mean is k - 1 and its
// standard deviation sqrt(2 (k - 1)).
double chi_square(const std::vector<int>& count, double expected) {
  double chi = 0;
  for (int c : count) chi += (c - expected) * (c - expected) / expected;
  return chi;
}

TEST(PathSampler, BitReverseMatchesTheDefinition) {
  for (uint x : {0u, 1u, 2u, 0x80000000u, 0x12345678u, 0xFFFFFFFFu}) {
    uint expected = 0;
    for (int b = 0; b < 32; ++b)
      if (x & (1u << b)) expected |= 1u << (31 - b);
    EXPECT_EQ(bitfieldReverse(x), expected);
  }
}

// The closed form of the second Sobol dimension equals its definition: direction numbers v_0 = 1/2,
// v_{k+1} = v_k ^ (v_k >> 1), XORed for the index's set bits.
TEST(PathSampler, SecondSobolDimensionMatchesItsDirectionNumbers) {
  uint x = 12345u;
  for (int n = 0; n < 20000; ++n) {
    x = hash_u32(x + uint(n));
    const uint index = n < 1000 ? uint(n) : x;
    uint expected = 0, v = 1u << 31;
    for (uint i = index; i != 0; i >>= 1, v ^= v >> 1)
      if (i & 1u) expected ^= v;
    ASSERT_EQ(sobol_second_dimension(index), expected) << "index " << index;
  }
}

// Across items (texels) one dimension is uniform: 64 bins, 64 k items, 5 standard deviations.
TEST(PathSampler, EveryDimensionIsUniformAcrossItems) {
  for (uint mode : {kSamplerSobol, kSamplerIndependent}) {
    for (uint sample : {0u, 5u}) {
      std::vector<int> first(64, 0), pair_x(64, 0), pair_y(64, 0), later(64, 0);
      const int items = 65536;
      for (int item = 0; item < items; ++item) {
        PathSampler s = path_sampler(11, uint64_t(item), sample, mode);
        float a = sample_1d(s);
        vec2 b = sample_2d(s);
        for (int skip = 0; skip < 6; ++skip) sample_1d(s);
        float c = sample_1d(s);
        for (float v : {a, b.x, b.y, c}) ASSERT_TRUE(v >= 0.0f && v < 1.0f);
        ++first[int(a * 64)], ++pair_x[int(b.x * 64)], ++pair_y[int(b.y * 64)], ++later[int(c * 64)];
      }
      const double bound = 63 + 5 * std::sqrt(2.0 * 63);
      EXPECT_LT(chi_square(first, items / 64.0), bound) << "mode " << mode;
      EXPECT_LT(chi_square(pair_x, items / 64.0), bound) << "mode " << mode;
      EXPECT_LT(chi_square(pair_y, items / 64.0), bound) << "mode " << mode;
      EXPECT_LT(chi_square(later, items / 64.0), bound) << "mode " << mode;
    }
  }
}

// One item's first 256 Sobol samples of a 2-D draw: one point in each cell of every elementary
// interval shape of area 1/256 (256x1, 128x2, ..., 1x256); the 1-D draws: one per 1/256 interval.
TEST(PathSampler, SobolSamplesOfOneItemFormANet) {
  for (uint64_t item : {0ull, 7ull, 123456ull}) {
    for (int dimension = 0; dimension < 4; ++dimension) {
      std::vector<vec2> points;
      std::vector<float> values;
      for (uint i = 0; i < 256; ++i) {
        PathSampler s = path_sampler(3, item, i, kSamplerSobol);
        for (int d = 0; d < dimension; ++d) sample_1d(s);
        points.push_back(sample_2d(s));
        values.push_back(sample_1d(s));
      }
      for (int log_x = 0; log_x <= 8; ++log_x) {
        const int nx = 1 << log_x, ny = 256 / nx;
        std::vector<int> cells(256, 0);
        for (vec2 p : points) ++cells[int(p.y * ny) * nx + int(p.x * nx)];
        for (int c : cells) ASSERT_EQ(c, 1) << "item " << item << " dimension " << dimension << " grid " << nx << "x" << ny;
      }
      std::vector<int> strata(256, 0);
      for (float v : values) ++strata[int(v * 256)];
      for (int c : strata) ASSERT_EQ(c, 1) << "item " << item << " dimension " << dimension;
    }
  }
}

// Two dimensions of one item are independent: over an item's first 1024 samples, the pairs of
// consecutive 1-D draws (and a 1-D draw with the next 2-D draw) fill a 16x16 grid as independent
// uniform pairs would (chi-square within 5 standard deviations). Without the per-dimension index
// shuffle, scrambled copies of one sequence share their leading digits and fail this badly.
TEST(PathSampler, DimensionsOfOneItemAreIndependent) {
  for (uint64_t item : {1ull, 99ull}) {
    std::vector<int> one_one(256, 0), one_two(256, 0);
    for (uint i = 0; i < 1024; ++i) {
      PathSampler s = path_sampler(8, item, i, kSamplerSobol);
      const float a = sample_1d(s), b = sample_1d(s);
      const vec2 c = sample_2d(s);
      ++one_one[int(a * 16) * 16 + int(b * 16)];
      ++one_two[int(b * 16) * 16 + int(c.x * 16)];
    }
    const double bound = 255 + 5 * std::sqrt(2.0 * 255);
    EXPECT_LT(chi_square(one_one, 4.0), bound) << "item " << item;
    EXPECT_LT(chi_square(one_two, 4.0), bound) << "item " << item;
  }
}

// The scramble differs per item: two items' first points are not the same.
TEST(PathSampler, ItemsAndSeedsGetTheirOwnScrambles) {
  PathSampler a = path_sampler(3, 1, 0, kSamplerSobol), b = path_sampler(3, 2, 0, kSamplerSobol);
  PathSampler c = path_sampler(4, 1, 0, kSamplerSobol);
  const vec2 pa = sample_2d(a), pb = sample_2d(b), pc = sample_2d(c);
  EXPECT_NE(pa.x, pb.x);
  EXPECT_NE(pa.x, pc.x);
}

// The mean of an item's first n Sobol points of a smooth integrand converges faster than n^-1/2: at
// n = 1024 its root mean square error over 256 items is well below the independent sampler's.
TEST(PathSampler, SobolIntegratesASmoothFunctionBetterThanIndependent) {
  auto f = [](vec2 u) { return std::cos(3.0f * u.x) * std::exp(u.y); };
  const double exact = std::sin(3.0) / 3.0 * (std::exp(1.0) - 1.0);
  double squared_error[2] = {0, 0};
  for (uint mode : {kSamplerSobol, kSamplerIndependent}) {
    for (uint64_t item = 0; item < 256; ++item) {
      double sum = 0;
      for (uint i = 0; i < 1024; ++i) {
        PathSampler s = path_sampler(5, item, i, mode);
        sum += f(sample_2d(s));
      }
      const double e = sum / 1024 - exact;
      squared_error[mode] += e * e / 256;
    }
  }
  // Independent: variance / n (about 1e-3 here); Sobol on a smooth integrand: about n^-1.5 or better.
  EXPECT_LT(squared_error[kSamplerSobol], 0.05 * squared_error[kSamplerIndependent]);
}

}  // namespace
}  // namespace exitance
