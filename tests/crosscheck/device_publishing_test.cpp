// What texels publish, composed on the device (VulkanIntegrator::publish, shaders/wavefront/publish.comp)
// against the host's rule (refresh/published_estimate.h publish_restart, publish_change) on the same
// estimates: the same choice per texel and the same sums, on lavapipe with validation on. The kept
// estimates are real accumulations of a lit box, perturbed per texel so that every branch of the
// rule is taken (no samples, one sample, the kept value far off or close, few refreshed samples).
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/runtime/refresh/published_estimate.h"
#include "support/atlas_box.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

IntegratorSettings settings(uint64_t seed, int recorded) {
  IntegratorSettings s;
  s.seed = seed;
  s.max_bounces = 3;
  s.recorded_bounces = recorded;
  return s;
}

// `e` with its texels perturbed by index: no samples (i % 7 == 0), one sample (i % 11 == 1), the
// mean scaled by `scale` (i % 3 == 2): sums and layers scaled alike, so the sums stay consistent.
LightmapEstimate perturbed(LightmapEstimate e, double scale) {
  const size_t n = e.texels.size();
  for (size_t i = 0; i < n; ++i) {
    TexelAccumulator& t = e.texels[i];
    double f = 1;
    if (i % 7 == 0) {
      t = TexelAccumulator{};
      f = 0;
    } else if (i % 11 == 1) {
      for (int c = 0; c < 3; ++c) t.total[c] /= t.samples, t.total_squared[c] = t.total[c] * t.total[c], t.direct[c] /= t.samples;
      f = 1.0 / t.samples;
      t.samples = 1;
    } else if (i % 3 == 2) {
      for (int c = 0; c < 3; ++c) t.total[c] *= scale, t.total_squared[c] *= scale * scale, t.direct[c] *= scale;
      f = scale;
    }
    if (f != 1)
      for (int k = 0; k < e.recorded_bounces; ++k)
        for (size_t c = 0; c < 3; ++c) e.bounces[(size_t(k) * n + i) * 3 + c] *= f;
  }
  return e;
}

// Same samples per texel; sums and layers equal to the last few bits (a device may fuse a multiply
// and an add where the host rounds twice).
void expect_same_estimate(const LightmapEstimate& device, const LightmapEstimate& host, const char* what) {
  ASSERT_EQ(device.texels.size(), host.texels.size()) << what;
  ASSERT_EQ(device.bounces.size(), host.bounces.size()) << what;
  auto close = [](double a, double b) { return std::fabs(a - b) <= 1e-12 * std::max(std::fabs(a), std::fabs(b)) + 1e-300; };
  size_t differing = 0;
  for (size_t i = 0; i < host.texels.size(); ++i) {
    bool same = device.texels[i].samples == host.texels[i].samples;
    for (int c = 0; c < 3; ++c)
      same = same && close(device.texels[i].total[c], host.texels[i].total[c]) &&
             close(device.texels[i].total_squared[c], host.texels[i].total_squared[c]);
    differing += !same;
  }
  for (size_t j = 0; j < host.bounces.size(); ++j) differing += !close(device.bounces[j], host.bounces[j]);
  EXPECT_EQ(differing, 0u) << what << ": texels or layers that differ from the host's rule";
}

struct Counts {
  uint64_t single = 0, sampled = 0;
};
Counts counts_of(const LightmapEstimate& e) {
  Counts c;
  for (const TexelAccumulator& t : e.texels) c.single += t.samples == 1, c.sampled += t.samples >= 2;
  return c;
}

TEST(DevicePublishing, EqualsTheHostRuleTexelForTexel) {
  const Vec3 le{0.6f, 0.5f, 0.4f}, black{0, 0, 0};
  const Vec3 emission[6] = {black, le, black, black, black, black};  // a glowing ceiling
  const testing::AtlasScene box = testing::atlas_box(0.6f, emission, 6);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  const int recorded = 2;

  // The kept estimates: 16 samples of another seed, perturbed.
  vk->start_progressive(box.gbuffer, settings(5, recorded));
  vk->add_samples(16);
  const LightmapEstimate kept = vk->progressive_estimate();
  const LightmapEstimate previous = perturbed(kept, 1.5), base = perturbed(kept, 1.02);
  ASSERT_GT(previous.texels.size(), 100u);

  vk->start_progressive(box.gbuffer, settings(9, recorded));
  const std::shared_ptr<DeviceLightmap> previous_on_device = vk->upload_lightmap(previous);
  const std::shared_ptr<DeviceLightmap> base_on_device = vk->upload_lightmap(base);
  EXPECT_EQ(vk->read_lightmap(*previous_on_device).bounces, previous.bounces) << "an upload and a read-back change nothing";

  size_t kept_texels = 0, refreshed_texels = 0;
  for (uint32_t samples : {3u, 9u}) {  // fewer than kRestartMinimumSamples, then more
    vk->add_samples(samples == 3 ? 3 : 6);
    const LightmapEstimate accumulation = vk->progressive_estimate();
    const std::string at = std::to_string(samples) + " refreshed samples";

    const LightmapEstimate host_restart = publish_restart(previous, accumulation);
    const PublishedLightmap restart = vk->publish(PublishMode::Restart, previous_on_device.get(), nullptr);
    expect_same_estimate(vk->read_lightmap(*restart.lightmap), host_restart, ("restart, " + at).c_str());
    EXPECT_EQ(restart.single_sample_texels, counts_of(host_restart).single) << at;
    EXPECT_EQ(restart.sampled_texels, counts_of(host_restart).sampled) << at;
    for (size_t i = 0; i < previous.texels.size(); ++i)
      if (previous.texels[i].samples > 0) {
        const bool kept_value = host_restart.texels[i].samples == previous.texels[i].samples &&
                                host_restart.texels[i].total[0] == previous.texels[i].total[0];
        kept_texels += kept_value, refreshed_texels += !kept_value;
      }

    const LightmapEstimate host_change = publish_change(previous, base, accumulation);
    const PublishedLightmap change = vk->publish(PublishMode::Change, previous_on_device.get(), base_on_device.get());
    expect_same_estimate(vk->read_lightmap(*change.lightmap), host_change, ("change, " + at).c_str());
    EXPECT_EQ(change.single_sample_texels, counts_of(host_change).single) << at;

    const PublishedLightmap plain = vk->publish(PublishMode::Accumulation, nullptr, nullptr);
    expect_same_estimate(vk->read_lightmap(*plain.lightmap), accumulation, ("accumulation, " + at).c_str());
  }
  // Both outcomes of the rule were exercised.
  EXPECT_GT(kept_texels, 0u);
  EXPECT_GT(refreshed_texels, 0u);
}

// A texel an edit covered: every refreshed sample 0 (publishing_rule.h's run of zeros). The box is
// black with a small one-sided emitter under its ceiling facing down, so the ceiling's texels see
// nothing lit and get exactly 0; the kept estimate shows them lit (as before an edit that covered
// them). Device and host choose alike, and the run of zeros replaces the kept value.
TEST(DevicePublishing, ACoveredTexelEqualsTheHostRule) {
  const Vec3 black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  const testing::AtlasScene box = testing::atlas_box(0.0f, emission, 6, 0.3f, Vec3{4, 4, 4});
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  vk->start_progressive(box.gbuffer, settings(5, 1));
  vk->add_samples(16);
  LightmapEstimate previous = vk->progressive_estimate();
  size_t ceiling = 0;
  for (size_t i = 0; i < previous.texels.size(); ++i) {
    TexelAccumulator& t = previous.texels[i];
    if (box.gbuffer.texels[i].instance != 1) continue;
    ASSERT_EQ(t.total[0], 0.0) << "a ceiling texel saw light: the test needs them dark";
    // Mean 0.3, per-sample variance 0.05 per channel: nine zeros are improbable unchanged (at most
    // (0.15 / 0.42)^9 = 1e-4), while the 3-sigma test alone keeps the value (0.27 < 4.27^2 x 0.026).
    for (int c = 0; c < 3; ++c) t.total[c] = t.samples * 0.3, t.total_squared[c] = t.samples * (0.09 + 0.05 * 15.0 / 16.0);
    ++ceiling;
  }
  ASSERT_GT(ceiling, 10u);
  vk->start_progressive(box.gbuffer, settings(9, 1));
  const std::shared_ptr<DeviceLightmap> previous_on_device = vk->upload_lightmap(previous);
  vk->add_samples(9);
  const LightmapEstimate accumulation = vk->progressive_estimate();
  const LightmapEstimate host = publish_restart(previous, accumulation);
  const PublishedLightmap restart = vk->publish(PublishMode::Restart, previous_on_device.get(), nullptr);
  expect_same_estimate(vk->read_lightmap(*restart.lightmap), host, "restart over covered texels");
  size_t covered_shown = 0;
  for (size_t i = 0; i < host.texels.size(); ++i)
    covered_shown += box.gbuffer.texels[i].instance == 1 && host.texels[i].samples == 9 && host.texels[i].total[0] == 0.0;
  EXPECT_EQ(covered_shown, ceiling) << "every covered texel shows its 9 zeros";
}

}  // namespace
}  // namespace exitance
