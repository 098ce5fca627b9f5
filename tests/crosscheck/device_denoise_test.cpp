// The texture-space filter of the indirect light on the device (VulkanIntegrator::denoise_indirect,
// shaders/wavefront/denoise_indirect.comp) against the host's (bundle/indirect_denoise.h) on the
// same estimate: the same texels filtered, the same neighbours counted and the same sums up to the
// rounding of exp and sqrt, on lavapipe with validation on. The estimate is a real accumulation of
// a lit box on a real atlas (six charts meeting at creases, which the filter must not cross), with
// five recorded layers (the kernel sums layers three per pass over the window: two passes here),
// some texels without samples and some with one; then the totals alone, as the page images take them.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/runtime/bundle/indirect_denoise.h"
#include "support/atlas_box.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

IntegratorSettings settings(uint64_t seed, int recorded) {
  IntegratorSettings s;
  s.seed = seed;
  s.max_bounces = 5;
  s.recorded_bounces = recorded;
  return s;
}

// No samples where i % 7 == 0, one sample where i % 11 == 1 (the mean kept, layers alike).
LightmapEstimate with_thin_texels(LightmapEstimate e) {
  const size_t n = e.texels.size();
  for (size_t i = 0; i < n; ++i) {
    TexelAccumulator& t = e.texels[i];
    double f = 1;
    if (i % 7 == 0) {
      t = TexelAccumulator{};
      f = 0;
    } else if (i % 11 == 1) {
      f = 1.0 / t.samples;
      for (int c = 0; c < 3; ++c) t.total[c] *= f, t.total_squared[c] = t.total[c] * t.total[c], t.direct[c] *= f;
      t.samples = 1;
    }
    if (f != 1)
      for (int k = 0; k < e.recorded_bounces; ++k)
        for (size_t c = 0; c < 3; ++c) e.bounces[(size_t(k) * n + i) * 3 + c] *= f;
  }
  return e;
}

// Relative agreement of float weights' sums (exp and sqrt may differ in the last bit or two).
bool close(double a, double b) { return std::fabs(a - b) <= 2e-6 * std::max(std::fabs(a), std::fabs(b)) + 1e-12; }

TEST(DeviceDenoise, EqualsTheHostFilter) {
  const Vec3 le{0.6f, 0.5f, 0.4f}, black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  // A small bright emitter under the ceiling: direct light with shadows of nothing, indirect light
  // that varies across each wall.
  const testing::AtlasScene box = testing::atlas_box(0.7f, emission, 12, 0.3f, le * 10.0f);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  const int recorded = 5;
  vk->start_progressive(box.gbuffer, settings(3, recorded));
  vk->add_samples(6);
  const LightmapEstimate estimate = with_thin_texels(vk->progressive_estimate());
  const size_t n = estimate.texels.size();
  ASSERT_GT(n, 500u);
  ASSERT_EQ(estimate.recorded_bounces, recorded);

  IndirectDenoiseReport host_report;
  const LightmapEstimate host = denoise_indirect(estimate, box.gbuffer, {.radius = 3}, &host_report);
  const std::shared_ptr<DeviceLightmap> uploaded = vk->upload_lightmap(estimate);
  DeviceDenoiseCounts counts;
  const LightmapEstimate device = vk->read_lightmap(*vk->denoise_indirect(*uploaded, box.gbuffer, 3, &counts));

  EXPECT_EQ(counts.texels, host_report.texels);
  EXPECT_NEAR(double(counts.neighbours) / double(counts.texels), host_report.mean_neighbours, 1e-9);
  EXPECT_GT(host_report.mean_neighbours, 10.0) << "the window found few neighbours: the test checks little";
  ASSERT_EQ(device.texels.size(), n);
  ASSERT_EQ(device.bounces.size(), host.bounces.size());
  size_t differing = 0, direct_changed = 0;
  for (size_t i = 0; i < n; ++i) {
    bool same = device.texels[i].samples == host.texels[i].samples;
    for (int c = 0; c < 3; ++c)
      same = same && close(device.texels[i].total[c], host.texels[i].total[c]) &&
             close(device.texels[i].total_squared[c], host.texels[i].total_squared[c]);
    differing += !same;
    for (size_t c = 0; c < 3; ++c) direct_changed += device.bounces[i * 3 + c] != estimate.bounces[i * 3 + c];
  }
  for (size_t j = 0; j < host.bounces.size(); ++j) differing += !close(device.bounces[j], host.bounces[j]);
  EXPECT_EQ(differing, 0u) << "texels or layers where the device's filter differs from the host's";
  EXPECT_EQ(direct_changed, 0u) << "layer 0 (the direct light) is kept exactly";

  // Totals only (what the page images read): the same totals, at a fraction of the work.
  const LightmapEstimate totals = vk->read_lightmap(*vk->denoise_indirect(*uploaded, box.gbuffer, 3, nullptr, true));
  size_t totals_differing = 0;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      totals_differing += !close(totals.texels[i].total[c], host.texels[i].total[c]) ||
                          !close(totals.texels[i].total_squared[c], host.texels[i].total_squared[c]) ||
                          totals.texels[i].samples != host.texels[i].samples;
  EXPECT_EQ(totals_differing, 0u);

  // Not a copy: the filter lowered the noise (the summed variance of the means) several times.
  double before = 0, after = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 v0 = estimate.variance_of_mean(i), v1 = device.variance_of_mean(i);
    before += v0.x + v0.y + v0.z, after += v1.x + v1.y + v1.z;
  }
  EXPECT_LT(after, before / 3) << "variance before " << before << ", after " << after;

  // Bad calls change nothing and say why.
  EXPECT_THROW(vk->denoise_indirect(*uploaded, box.gbuffer, 0, nullptr), std::invalid_argument);
  EXPECT_THROW(vk->denoise_indirect(*uploaded, box.gbuffer, 17, nullptr), std::invalid_argument);
  TexelGBuffer fewer = box.gbuffer;
  fewer.texels.pop_back();
  EXPECT_THROW(vk->denoise_indirect(*uploaded, fewer, 3, nullptr), std::invalid_argument);
}

// After a start with moved texels (update_texels), the device filter reads where they are now.
TEST(DeviceDenoise, FollowsMovedTexels) {
  const Vec3 le{0.6f, 0.5f, 0.4f}, black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  const testing::AtlasScene box = testing::atlas_box(0.7f, emission, 12, 0.3f, le * 10.0f);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  vk->start_progressive(box.gbuffer, settings(3, 1));
  vk->add_samples(6);
  const LightmapEstimate estimate = vk->progressive_estimate();
  const std::shared_ptr<DeviceLightmap> uploaded = vk->upload_lightmap(estimate);
  vk->denoise_indirect(*uploaded, box.gbuffer, 3, nullptr);  // the records uploaded as they are

  // Every other texel of the floor's chart lifted off its plane: none of them mixes with the rest now.
  TexelGBuffer moved = box.gbuffer;
  std::vector<uint32_t> lifted;
  for (uint32_t i = 0; i < moved.texels.size(); ++i)
    if (moved.texels[i].instance == 0 && i % 2 == 0) moved.texels[i].position.y += 0.5f, lifted.push_back(i);
  ASSERT_FALSE(lifted.empty());
  vk->update_texels(moved, lifted);
  IndirectDenoiseReport host_report;
  const LightmapEstimate host = denoise_indirect(estimate, moved, {.radius = 3}, &host_report);
  DeviceDenoiseCounts counts;
  const LightmapEstimate device = vk->read_lightmap(*vk->denoise_indirect(*uploaded, moved, 3, &counts));
  EXPECT_NEAR(double(counts.neighbours) / double(counts.texels), host_report.mean_neighbours, 1e-9);
  size_t differing = 0;
  for (size_t i = 0; i < host.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) differing += !close(device.texels[i].total[c], host.texels[i].total[c]);
  EXPECT_EQ(differing, 0u);
}

}  // namespace
}  // namespace exitance
