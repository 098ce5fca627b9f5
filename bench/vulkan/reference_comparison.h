// Cross-check of a Vulkan bake against a CPU reference bake of the same texels, for machines where
// only the Vulkan half can run (the GPU machine): the reference is computed here and written as
// per-texel means and variances of the mean (float32, RGB), the comparison runs there.
// Same statistics as tests/crosscheck: region z-tests with both estimators' variances, relMSE.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/cpu_reference_integrator.h"

namespace exitance::replay {

// Layout: uint64 texel count n, then 3n floats of means, then 3n floats of variances of the mean.
inline void write_reference(const std::string& path, const LightmapEstimate& estimate) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + path);
  const uint64_t n = estimate.texels.size();
  std::vector<float> values(n * 6);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 m = estimate.mean_total(i), v = estimate.variance_of_mean(i);
    for (int c = 0; c < 3; ++c) values[i * 3 + size_t(c)] = m[c], values[3 * n + i * 3 + size_t(c)] = v[c];
  }
  const bool ok = std::fwrite(&n, 8, 1, f) == 1 && std::fwrite(values.data(), 4, values.size(), f) == values.size();
  std::fclose(f);
  if (!ok) throw std::runtime_error("cannot write " + path);
}

struct ReferenceComparison {
  size_t regions = 0;
  double max_abs_z = 0;
  double rel_mse = 0;        // mean (a - b)^2 / (b^2 + 1e-3)
  double noise_rel_mse = 0;  // what both estimators' variances alone would give
};

inline ReferenceComparison compare_with_reference(const std::string& path, const LightmapEstimate& estimate,
                                                  size_t regions) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error("cannot read " + path);
  uint64_t n = 0;
  bool ok = std::fread(&n, 8, 1, f) == 1 && n == estimate.texels.size();
  std::vector<float> ref(ok ? n * 6 : 0);
  ok = ok && std::fread(ref.data(), 4, ref.size(), f) == ref.size();
  std::fclose(f);
  if (!ok) throw std::runtime_error(path + ": not a reference for these texels");
  ReferenceComparison result;
  result.regions = std::min<size_t>(regions, n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 m = estimate.mean_total(i), v = estimate.variance_of_mean(i);
    for (int c = 0; c < 3; ++c) {
      const double b = ref[i * 3 + size_t(c)], d = double(m[c]) - b, w = 1.0 / (b * b + 1e-3);
      result.rel_mse += d * d * w;
      result.noise_rel_mse += (double(v[c]) + ref[3 * n + i * 3 + size_t(c)]) * w;
    }
  }
  result.rel_mse /= double(3 * n);
  result.noise_rel_mse /= double(3 * n);
  // Regions: consecutive runs of texels (Morton order, so spatially compact), per channel.
  for (size_t r = 0; r < result.regions; ++r) {
    const size_t begin = r * n / result.regions, end = (r + 1) * n / result.regions;
    for (int c = 0; c < 3; ++c) {
      double d = 0, var = 0;
      for (size_t i = begin; i < end; ++i) {
        d += double(estimate.mean_total(i)[c]) - ref[i * 3 + size_t(c)];
        var += double(estimate.variance_of_mean(i)[c]) + ref[3 * n + i * 3 + size_t(c)];
      }
      if (var > 0) result.max_abs_z = std::max(result.max_abs_z, std::fabs(d) / std::sqrt(var));
    }
  }
  return result;
}

}  // namespace exitance::replay
