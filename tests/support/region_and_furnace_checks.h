// Checks the unbiasedness tests share: per-texel luminance of E/pi, its mean per region (instance),
// and the white furnace's closed form Le / (1 - rho) over independent seeds.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "support/independent_estimates.h"

namespace exitance::testing {

// Luminance of E/pi per texel of one run.
inline std::vector<double> luminance_means(const LightmapEstimate& e) {
  std::vector<double> m(e.texels.size());
  for (size_t i = 0; i < m.size(); ++i) m[i] = luminance(e.mean_total(i));
  return m;
}

// Per-texel values averaged per instance (region).
inline std::map<uint32_t, double> region_means(const TexelGBuffer& gbuffer, const std::vector<double>& texel) {
  std::map<uint32_t, double> sum, count;
  for (size_t i = 0; i < texel.size(); ++i) sum[gbuffer.texels[i].instance] += texel[i], count[gbuffer.texels[i].instance] += 1;
  for (auto& [region, s] : sum) s /= count[region];
  return sum;
}

// Per region, the means of `guided` and `unguided` runs (independent seeds each) agree within
// z_limit standard errors of their difference. Returns the median over regions of that standard
// error relative to the unguided mean (infinite for a region whose mean is 0): the caller checks
// the test's power with it.
inline double expect_region_means_agree(const char* tag, const std::string& label,
                                        const std::map<uint32_t, std::vector<double>>& guided,
                                        const std::map<uint32_t, std::vector<double>>& unguided, double z_limit) {
  std::vector<double> relative_se;
  for (const auto& entry : unguided) {
    const uint32_t region = entry.first;
    const MeanAndError su = mean_and_standard_error(entry.second), sg = mean_and_standard_error(guided.at(region));
    const double se = std::hypot(su.standard_error, sg.standard_error);
    const double z = se > 0 ? (sg.mean - su.mean) / se : (sg.mean == su.mean ? 0.0 : INFINITY);
    std::printf("[%s] %s region %u: unguided %.5g guided %.5g (SE %.2g) z %+.2f\n", tag, label.c_str(), region, su.mean,
                sg.mean, se, z);
    EXPECT_LE(std::fabs(z), z_limit) << label << " region " << region;
    relative_se.push_back(su.mean > 0 ? se / su.mean : INFINITY);
  }
  if (relative_se.empty()) return INFINITY;
  std::sort(relative_se.begin(), relative_se.end());
  return relative_se[relative_se.size() / 2];
}

// The mean over texels of each channel, over `seeds` runs of `bake(seed)`, equals le / (1 - rho)
// within z_limit standard errors, and the test can resolve 1 % (the standard error is below it).
inline void expect_furnace_closed_form(const char* label, Vec3 le, float rho, int seeds, double z_limit,
                                       const std::function<LightmapEstimate(uint64_t seed)>& bake) {
  std::vector<LightmapEstimate> runs;
  for (int seed = 0; seed < seeds; ++seed) runs.push_back(bake(uint64_t(seed)));
  for (int c = 0; c < 3; ++c) {
    std::vector<double> means;
    for (const LightmapEstimate& e : runs) {
      double sum = 0;
      for (size_t i = 0; i < e.texels.size(); ++i) sum += e.mean_total(i)[c];
      means.push_back(sum / double(e.texels.size()));
    }
    const MeanAndError s = mean_and_standard_error(means);
    const double exact = le[c] / (1 - rho);
    std::printf("[%s] furnace ch%d: exact %.5g estimate %.6g SE %.2g\n", label, c, exact, s.mean, s.standard_error);
    EXPECT_LE(std::fabs(s.mean - exact), z_limit * s.standard_error + 1e-6 * exact);
    EXPECT_LT(s.standard_error, 0.01 * exact);
  }
}

}  // namespace exitance::testing
