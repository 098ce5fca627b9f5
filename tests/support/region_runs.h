// Per-region means of independent runs of two estimators, and the z-test that they agree (the Vulkan
// guiding crosschecks: guided against unguided, or against the CPU's guided estimate).
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "support/independent_estimates.h"
#include "support/region_and_furnace_checks.h"

namespace exitance::testing {

using RegionRuns = std::map<uint32_t, std::vector<double>>;

// One run's per-region luminance means appended to `runs`.
inline void add_regions(const TexelGBuffer& gbuffer, const LightmapEstimate& e, RegionRuns& runs) {
  for (const auto& entry : region_means(gbuffer, luminance_means(e))) runs[entry.first].push_back(entry.second);
}

// One run's per-region luminance means of bounce layer `layer` (LightmapEstimate::mean_bounce) appended to `runs`.
inline void add_layer_regions(const TexelGBuffer& gbuffer, const LightmapEstimate& e, int layer, RegionRuns& runs) {
  std::vector<double> texel(gbuffer.texels.size());
  for (size_t i = 0; i < texel.size(); ++i) texel[i] = luminance(e.mean_bounce(layer, i));
  for (const auto& entry : region_means(gbuffer, texel)) runs[entry.first].push_back(entry.second);
}

// Per region, the means of two sets of independent runs agree within `z_limit` (printed under
// `prefix`). Returns the median over regions of the relative standard error of the difference.
inline double expect_regions_agree(const char* prefix, const std::string& label, const RegionRuns& reference,
                                   const RegionRuns& tested, double z_limit) {
  std::vector<double> relative_se;
  for (const auto& entry : reference) {
    const MeanAndError r = mean_and_standard_error(entry.second);
    const MeanAndError t = mean_and_standard_error(tested.at(entry.first));
    const double se = std::hypot(r.standard_error, t.standard_error);
    const double z = se > 0 ? (t.mean - r.mean) / se : (t.mean == r.mean ? 0.0 : INFINITY);
    std::printf("[%s] %s region %u: reference %.5g tested %.5g (SE %.2g) z %+.2f\n", prefix, label.c_str(),
                entry.first, r.mean, t.mean, se, z);
    EXPECT_LE(std::fabs(z), z_limit) << label << " region " << entry.first;
    relative_se.push_back(r.mean > 0 ? se / r.mean : INFINITY);
  }
  std::sort(relative_se.begin(), relative_se.end());
  return relative_se[relative_se.size() / 2];
}

}  // namespace exitance::testing
