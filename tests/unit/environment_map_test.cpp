// The image-sky sampler the CPU reference and the Vulkan kernels share (runtime/common/.../
// environment_map.h, through EnvironmentSampler's CDFs), checked in C++: sampled directions fall into
// (u, v) bins as often as the pdf integrated over the bin says (chi-square), never into black texels,
// and report the pdf that pdf() gives them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "exitance/common/environment_map.h"
#include "exitance/common/rng.h"
#include "exitance/runtime/environment_sampler.h"

namespace exitance {
namespace {

// 16 x 8 texels: the top row black (a zero marginal cell), a black block, one bright texel, the rest varied.
Texture test_sky() {
  Texture sky;
  sky.width = 16;
  sky.height = 8;
  sky.rgb.resize(16 * 8 * 3);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      float v = float((size_t(y * 16 + x) * 7919) % 13) + 0.1f;
      if (y == 0 || (y >= 3 && y < 5 && x >= 4 && x < 9)) v = 0.0f;
      if (y == 6 && x == 12) v = 40.0f;
      for (int c = 0; c < 3; ++c) sky.rgb[size_t(y * 16 + x) * 3 + size_t(c)] = v * (1.0f + 0.2f * float(c));
    }
  return sky;
}

// Upper chi-square quantile for `df` degrees of freedom at the normal quantile z (Wilson-Hilferty).
double chi_square_quantile(double df, double z) {
  const double a = 2.0 / (9.0 * df);
  return df * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

TEST(EnvironmentMap, SampledDirectionsFollowThePdf) {
  const Texture sky = test_sky();
  const EnvironmentSampler sampler(sky);
  ASSERT_TRUE(sampler.enabled());
  // 2 x 2 bins per texel; a bin's probability is the integral of the solid-angle pdf over it,
  // d omega = 2 pi^2 sin(theta) du dv (midpoint rule, 4 x 4 points per bin).
  const int bins_u = 32, bins_v = 16, points = 4;
  std::vector<double> expected(size_t(bins_u * bins_v), 0.0);
  for (int bv = 0; bv < bins_v; ++bv)
    for (int bu = 0; bu < bins_u; ++bu)
      for (int j = 0; j < points; ++j)
        for (int i = 0; i < points; ++i) {
          const Vec2 uv{(float(bu) + (float(i) + 0.5f) / points) / bins_u, (float(bv) + (float(j) + 0.5f) / points) / bins_v};
          const double jacobian = 2 * kPi * kPi * std::sin(kPi * double(uv.y));
          expected[size_t(bv * bins_u + bu)] +=
              double(sampler.pdf(equirect_to_direction(uv))) * jacobian / (double(bins_u * bins_v) * points * points);
        }
  double total = 0;
  for (double p : expected) total += p;
  EXPECT_NEAR(total, 1.0, 1e-4);

  const int n = 400000;
  std::vector<int> counts(expected.size(), 0);
  int unusable = 0;
  Pcg32 rng = pcg_init(13, 1, 0);
  for (int k = 0; k < n; ++k) {
    const float u1 = pcg_uniform(rng);
    const float u2 = pcg_uniform(rng);
    float pdf = 0;
    const Vec3 d = sampler.sample(u1, u2, pdf);
    ASSERT_EQ(pdf, sampler.pdf(d));
    // A direction on a texel edge may round into a black neighbour: pdf 0, which the integrator skips.
    if (!(pdf > 0)) {
      ++unusable;
      continue;
    }
    const Vec2 uv = direction_to_equirect(d);
    ++counts[size_t(equirect_cell(uv.y, bins_v) * bins_u + equirect_cell(uv.x, bins_u))];
  }
  // Each unusable sample is probability mass the estimator loses: a relative bias bound, kept far
  // below any cross-check's noise (8 of 400 000 here, from float round trips at black texels' edges).
  EXPECT_LE(unusable, n / 10000);
  double chi2 = 0;
  int cells = 0;
  for (size_t b = 0; b < expected.size(); ++b) {
    if (expected[b] <= 0) {
      EXPECT_EQ(counts[b], 0) << "bin " << b << " has pdf 0";
      continue;
    }
    const double e = expected[b] * n;
    chi2 += (counts[b] - e) * (counts[b] - e) / e;
    ++cells;
  }
  // The black texels (top row, the block) are 4 x (16 + 10) bins with pdf 0.
  EXPECT_EQ(cells, bins_u * bins_v - 4 * 26);
  // Under the null hypothesis chi2 exceeds this with probability ~1e-6.
  EXPECT_LT(chi2, chi_square_quantile(cells - 1, 4.75)) << "cells " << cells;
  std::printf("[environment map] chi-square %.1f over %d bins (limit %.1f), %d unusable of %d\n", chi2, cells,
              chi_square_quantile(cells - 1, 4.75), unusable, n);
}

TEST(EnvironmentMap, ExtremeRandomNumbersGiveUsableDirections) {
  const Texture sky = test_sky();
  const EnvironmentSampler sampler(sky);
  for (float u1 : {0.0f, 0.5f, 0.99999994f})
    for (float u2 : {0.0f, 0.5f, 0.99999994f}) {
      float pdf = -1;
      const Vec3 d = sampler.sample(u1, u2, pdf);
      EXPECT_NEAR(length(d), 1.0f, 1e-5f);
      EXPECT_TRUE(std::isfinite(pdf) && pdf >= 0.0f) << u1 << " " << u2;
      // Inside a cell (u = 0.5) the direction is well away from any black texel.
      if (u1 == 0.5f && u2 == 0.5f) EXPECT_GT(pdf, 0.0f);
    }
}

TEST(EnvironmentMap, MappingRoundTripsAndPicksTheTexel) {
  for (float v : {0.1f, 0.37f, 0.5f, 0.93f})
    for (float u : {0.02f, 0.25f, 0.5f, 0.81f}) {
      const Vec2 back = direction_to_equirect(equirect_to_direction({u, v}));
      EXPECT_NEAR(back.x, u, 1e-5f);
      EXPECT_NEAR(back.y, v, 1e-5f);
    }
  // Row 0 is +Y; u = 0.5 looks along -Z.
  EXPECT_EQ(environment_texel({0, 1, 0}, 16, 8) / 16, 0u);
  EXPECT_EQ(environment_texel({0, -1, 0}, 16, 8) / 16, 7u);
  EXPECT_EQ(environment_texel({0, 0.01f, -1}, 16, 8), 3u * 16u + 8u);
}

}  // namespace
}  // namespace exitance
