// A probe just above the lit floor of the Cornell-style room must read, for the up normal, the
// E/pi of the floor texel below it (DESIGN §6, issue 4). Two checks:
// 1. The probe's own rays, cosine-weighted for the up normal (ProbeEstimate's axis irradiance),
//    against the texel's cosine-weighted paths: different estimators of the same irradiance, so
//    a z-test on independent repeats (seeds).
// 2. The L2 SH evaluation against that irradiance: L2 truncation is a bias of the basis, not
//    noise. Convolving L with the clamped cosine truncated to bands 0-2 differs from the exact
//    kernel max(cos, 0) by at most 3/32 (at the horizon), so |E_L2 - E| / pi <= 3/32 * (1/pi) *
//    integral of L = 3/32 * c00 * sqrt(4 pi) / pi, plus 4 SE of noise.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/common/sampling.h"
#include "support/independent_estimates.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

constexpr int kRepeats = 32;  // the probe estimate is skewed (rare direct hits of the small light): many repeats

using testing::MeanAndError;
using testing::mean_and_standard_error;

TEST(ProbeVsLightmap, ProbeAboveCornellFloorMatchesTheTexelBelow) {
  Diagnostics diagnostics;
  const PreparedScene prepared =
      prepare_scene_for_lighting(std::string(EXITANCE_SAMPLE_DIR) + "/cornell_room.gltf", "", AtlasSettings{}, diagnostics);
  const CpuReferenceIntegrator integrator(prepared.scene);
  // Open floor in front of the short box and away from the walls, and one in the back-right corner region.
  for (const Vec3 floor_point : {Vec3{-1.2f, 0.0f, 1.2f}, Vec3{1.3f, 0.0f, -1.3f}}) {
    TexelGBuffer texel;
    texel.texels.push_back(testing::texel_at(floor_point, {0, 1, 0}));
    const Vec3 probe = floor_point + Vec3{0, 0.01f, 0};
    std::vector<double> texel_values[3], probe_values[3], sh_minus_probe[3], sh_bound[3];
    for (int r = 0; r < kRepeats; ++r) {
      IntegratorSettings settings;
      settings.seed = uint64_t(100 + r);
      settings.spp = 2048;
      const Vec3 texel_mean = integrator.bake(texel, settings).mean_total(0);
      settings.spp = 4096;
      const ProbeEstimate estimate = integrator.bake_probes({probe}, settings);
      const Vec3 up = estimate.mean_axis_irradiance_over_pi(0, 2);
      const Vec3 sh_up = sh_irradiance_over_pi(estimate.mean(0), {0, 1, 0});
      for (int c = 0; c < 3; ++c) {
        texel_values[c].push_back(texel_mean[c]);
        probe_values[c].push_back(up[c]);
        sh_minus_probe[c].push_back(sh_up[c] - up[c]);
        sh_bound[c].push_back(3.0 / 32.0 * estimate.mean(0)[0][c] * std::sqrt(4.0 * kPi) / kPi);
      }
    }
    for (int c = 0; c < 3; ++c) {
      const MeanAndError t = mean_and_standard_error(texel_values[c]), p = mean_and_standard_error(probe_values[c]);
      const double se = std::sqrt(t.standard_error * t.standard_error + p.standard_error * p.standard_error);
      const double z = (p.mean - t.mean) / se;
      const MeanAndError d = mean_and_standard_error(sh_minus_probe[c]), bound = mean_and_standard_error(sh_bound[c]);
      std::printf("[probe-vs-texel] (%.1f, %.1f) ch%d texel %.5f (SE %.2g) probe rays %.5f (SE %.2g) z %+.2f; "
                  "L2 SH minus rays %+.5f (SE %.2g), bound %.5f\n",
                  floor_point.x, floor_point.z, c, t.mean, t.standard_error, p.mean, p.standard_error, z, d.mean,
                  d.standard_error, bound.mean);
      EXPECT_LE(std::fabs(z), 4.0);
      EXPECT_LE(se, 0.03 * t.mean) << "standard error implausibly large";
      EXPECT_LE(std::fabs(d.mean), bound.mean + 4.0 * (d.standard_error + bound.standard_error));
    }
  }
}

}  // namespace
}  // namespace exitance
