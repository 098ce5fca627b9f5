// The math in runtime/common, compiled as C++: the same text the shaders compile (dialect.h), so
// these tests cover the GPU's sampling, offsets and distributions too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "exitance/common/distribution.h"
#include "exitance/common/ray_offset.h"
#include "exitance/common/rng.h"
#include "exitance/common/sampling.h"
#include "exitance/common/spherical_harmonics_basis.h"

namespace exitance {
namespace {

TEST(CommonMath, NextFloatTowardIsNextafter) {
  Pcg32 rng = pcg_init(4, 5, 6);
  for (int i = 0; i < 100000; ++i) {
    const uint bits = pcg_next(rng);
    const float x = uintBitsToFloat(bits);
    if (!std::isfinite(x) || std::isinf(std::nextafter(x, INFINITY)) || std::isinf(std::nextafter(x, -INFINITY))) continue;
    ASSERT_EQ(floatBitsToUint(next_float_toward(x, 1.0f)), floatBitsToUint(std::nextafter(x, INFINITY))) << x;
    ASSERT_EQ(floatBitsToUint(next_float_toward(x, -1.0f)), floatBitsToUint(std::nextafter(x, -INFINITY))) << x;
    ASSERT_EQ(floatBitsToUint(next_float_toward(x, 0.0f)), bits);
  }
  EXPECT_EQ(next_float_toward(0.0f, 1.0f), std::nextafter(0.0f, 1.0f));
  EXPECT_EQ(next_float_toward(-0.0f, -1.0f), std::nextafter(0.0f, -1.0f));
}

TEST(CommonMath, OffsetLeavesTheSurfaceOnTheNormalSide) {
  Pcg32 rng = pcg_init(7, 8, 9);
  for (int i = 0; i < 10000; ++i) {
    const float scale = std::pow(10.0f, 8.0f * pcg_uniform(rng) - 3.0f);
    const Vec3 p{(pcg_uniform(rng) - 0.5f) * scale, (pcg_uniform(rng) - 0.5f) * scale, (pcg_uniform(rng) - 0.5f) * scale};
    const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
    const Vec3 n = uniform_sphere(u1, u2);
    const Vec3 o = offset_ray_origin(p, n, scale);
    ASSERT_GT(dot(o - p, n), 0.0f);
  }
}

TEST(CommonMath, UniformIsInUnitIntervalAndStreamsDiffer) {
  Pcg32 a = pcg_init(1, 2, 3), b = pcg_init(1, 2, 4), c = pcg_init(1, 3, 3);
  int same_b = 0, same_c = 0;
  for (int i = 0; i < 1000; ++i) {
    const float x = pcg_uniform(a);
    ASSERT_GE(x, 0.0f);
    ASSERT_LT(x, 1.0f);
    same_b += x == pcg_uniform(b);
    same_c += x == pcg_uniform(c);
  }
  EXPECT_LT(same_b, 5);
  EXPECT_LT(same_c, 5);
  Pcg32 again = pcg_init(1, 2, 3), first = pcg_init(1, 2, 3);
  for (int i = 0; i < 100; ++i) ASSERT_EQ(pcg_next(again), pcg_next(first));
}

// sample_cdf is the upper bound of u in the CDF, stepped back over zero-probability cells.
TEST(CommonMath, SampleCdfMatchesUpperBoundAndSkipsEmptyCells) {
  const std::vector<double> weights = {0.0, 2.0, 0.0, 0.0, 1.0, 1.0, 0.0};
  std::vector<double> cdf(weights.size() + 1, 0.0);
  for (size_t i = 0; i < weights.size(); ++i) cdf[i + 1] = cdf[i] + weights[i] / 4.0;
  Pcg32 rng = pcg_init(11, 12, 13);
  std::vector<int> counts(weights.size(), 0);
  const int n = 40000;
  for (int k = 0; k < n; ++k) {
    const float u = pcg_uniform(rng);
    float pmf = 0;
    const uint i = sample_cdf(cdf.data(), uint(weights.size()), u, pmf);
    ASSERT_GT(weights[i], 0.0) << "u " << u;
    ASSERT_FLOAT_EQ(pmf, float(weights[i] / 4.0));
    const size_t bound = size_t(std::upper_bound(cdf.begin(), cdf.end(), double(u)) - cdf.begin()) - 1;
    ASSERT_EQ(i, bound);
    ++counts[i];
  }
  // Frequencies within 5 standard errors of the probabilities.
  for (size_t i = 0; i < weights.size(); ++i) {
    const double p = weights[i] / 4.0, se = std::sqrt(p * (1 - p) / n);
    EXPECT_NEAR(double(counts[i]) / n, p, 5 * se + 1e-12) << "cell " << i;
  }
  float pmf = 0;
  EXPECT_EQ(sample_cdf(cdf.data(), uint(weights.size()), 0.99999994f, pmf), 5u);  // past the last non-empty cell
}

TEST(CommonMath, OrthonormalBasisIncludingNegativeZero) {
  for (const Vec3 n : {Vec3{0, 0, 1}, Vec3{0, 0, -1}, Vec3{0, 0, -0.0f}, normalize(Vec3{1, 2, 3}), normalize(Vec3{-1, 0, -1e-8f})}) {
    if (!(length(n) > 0)) continue;
    Vec3 t, b;
    orthonormal_basis(n, t, b);
    EXPECT_NEAR(dot(t, t), 1.0f, 1e-5f);
    EXPECT_NEAR(dot(b, b), 1.0f, 1e-5f);
    EXPECT_NEAR(dot(t, b), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(t, n), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(b, n), 0.0f, 1e-5f);
  }
}

// The probe directions of a complete stratified set put exactly one sample in each cell of the
// equal-area (z, phi) grid.
TEST(CommonMath, ProbeDirectionsStratifyTheSphere) {
  const uint count = 256, m = 16;
  std::vector<int> cells(m * m, 0);
  Pcg32 rng = pcg_init(3, 3, 3);
  for (uint s = 0; s < count; ++s) {
    const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
    const Vec3 d = probe_direction(s, count, u1, u2);
    EXPECT_NEAR(length(d), 1.0f, 1e-5f);
    const float zu = (1.0f - d.z) * 0.5f;
    float phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2 * kPi;
    const uint cz = std::min(m - 1, uint(zu * float(m))), cp = std::min(m - 1, uint(phi / (2 * kPi) * float(m)));
    ++cells[cp * m + cz];
  }
  for (int c : cells) EXPECT_EQ(c, 1);
}

TEST(CommonMath, ShCosineLobeFactors) {
  EXPECT_FLOAT_EQ(sh_cosine_lobe_over_pi(0), 1.0f);
  EXPECT_FLOAT_EQ(sh_cosine_lobe_over_pi(1), 2.0f / 3.0f);
  EXPECT_FLOAT_EQ(sh_cosine_lobe_over_pi(2), 0.25f);
  EXPECT_FLOAT_EQ(kShSphereMeasure, 4.0f * kPi);
}

}  // namespace
}  // namespace exitance
