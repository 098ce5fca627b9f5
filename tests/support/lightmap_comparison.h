// Two lightmap estimates of the same texels from independent runs (two backends, or one backend
// and the reference): per region of `group` consecutive texels (Morton order keeps them close), a
// z-test with the variances of both (|z| < 4) catches real bias, and relMSE between the two catches
// gross errors. Sample counts must match; the first estimate must be finite and have traced rays.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "exitance/runtime/core/estimates.h"

namespace exitance::testing {

struct Comparison {
  double worst_z = 0;
  double rel_mse = 0;
};

inline Comparison compare_estimates(const LightmapEstimate& gpu, const LightmapEstimate& cpu, size_t group, const char* what) {
  Comparison c;
  const size_t n = cpu.texels.size();
  EXPECT_EQ(gpu.texels.size(), n);
  size_t regions = 0;
  for (size_t begin = 0; begin < n; begin += group) {
    const size_t end = std::min(n, begin + group);
    for (int ch = 0; ch < 3; ++ch) {
      double a = 0, b = 0, va = 0, vb = 0;
      for (size_t i = begin; i < end; ++i) {
        a += gpu.mean_total(i)[ch], b += cpu.mean_total(i)[ch];
        va += gpu.variance_of_mean(i)[ch], vb += cpu.variance_of_mean(i)[ch];
      }
      const double diff = std::fabs(a - b), se = std::sqrt(va + vb);
      const double rounding = 1e-5 * std::fabs(b) + 1e-9 * double(end - begin);
      if (diff <= rounding) continue;
      const double z = se > 0 ? diff / se : INFINITY;
      c.worst_z = std::max(c.worst_z, z);
      EXPECT_LT(z, 4.0) << what << ": region " << begin << ".." << end << " channel " << ch << " gpu " << a / double(end - begin)
                        << " cpu " << b / double(end - begin) << " SE " << se / double(end - begin);
    }
    ++regions;
  }
  for (size_t i = 0; i < n; ++i)
    for (int ch = 0; ch < 3; ++ch) {
      const double a = gpu.mean_total(i)[ch], b = cpu.mean_total(i)[ch];
      c.rel_mse += (a - b) * (a - b) / (b * b + 1e-3);
    }
  c.rel_mse /= double(3 * n);
  for (size_t i = 0; i < n; ++i) EXPECT_EQ(gpu.texels[i].samples, cpu.texels[i].samples) << what << " texel " << i;
  EXPECT_EQ(gpu.nonfinite_samples, 0u);
  EXPECT_GT(gpu.rays, 0u);
  std::printf("[crosscheck] %-28s texels %zu regions %zu worst |z| %.2f relMSE %.3g%% rays gpu %llu cpu %llu\n", what, n,
              regions, c.worst_z, 100.0 * c.rel_mse, (unsigned long long)gpu.rays, (unsigned long long)cpu.rays);
  return c;
}

}  // namespace exitance::testing
