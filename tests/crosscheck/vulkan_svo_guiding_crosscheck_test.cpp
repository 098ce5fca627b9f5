// SVO path guiding (--guiding svo, issue 11) on the Vulkan backend: the device descends the octree to
// its bin, samples the fields the host built (core/svo_guiding_fields.h, the CPU reference's code)
// and counts its vertices for the next rebuild (docs/lighting-core.md, "SVO guiding"). Forced on, it
// converges to the furnace's closed form, to Vulkan's unguided path tracer (a small bright emitter:
// NEE + MIS against the mixture pdf; the Cornell room; ajar_room) and to the CPU's SVO-guided
// estimate, per region; results are bit-identical per seed. Validation layers on; no device: SKIP.
//
// Standard errors come from independent seeds (kSeeds per estimator): guided samples of one texel
// depend on fields built from all texels. kZLimit = 5: two 8-seed means (Welch, ~14 degrees of
// freedom) differ by 5 SE with two-sided p ~ 2e-4 per region; with up to ~25 regions per test a
// false alarm stays below ~0.5 %; the furnace tests one 8-seed mean against the closed form (t with
// 7 dof): p ~ 2e-3 per channel. Each region test checks its power: a 10 % bias in the median region
// must exceed kZLimit SEs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/runtime/core/svo_guiding_fields.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/atlas_box.h"
#include "support/independent_estimates.h"
#include "support/guiding_octree.h"
#include "support/region_and_furnace_checks.h"
#include "support/region_runs.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

constexpr double kZLimit = 5.0;
constexpr int kSeeds = 8;
constexpr double kDetectableBias = 0.10;

IntegratorSettings settings(uint32_t spp, uint64_t seed, GuidingMode guiding, const formats::SparseVoxelOctree* octree,
                            float mix = 0.5f) {
  IntegratorSettings s;
  s.spp = spp;
  s.seed = seed;
  s.guiding = guiding;
  s.guiding_mix = mix;
  s.guiding_octree = octree;
  return s;
}

// Vulkan SVO-guided against Vulkan unguided (and, with `cpu_too`, against the CPU's SVO-guided estimate).
void expect_guided_agrees(const std::string& label, const Scene& scene, const TexelGBuffer& gbuffer, float density,
                          uint32_t spp, float mix, bool cpu_too) {
  CREATE_VULKAN_OR_SKIP(vk, scene);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(scene, density);
  testing::RegionRuns guided, unguided, cpu_guided;
  uint64_t guided_vertices = 0, texel_samples = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const LightmapEstimate g = vk->bake(gbuffer, settings(spp, uint64_t(seed), GuidingMode::Svo, &octree, mix));
    const LightmapEstimate u = vk->bake(gbuffer, settings(spp, uint64_t(seed) + 1000, GuidingMode::Off, nullptr));
    EXPECT_EQ(g.nonfinite_samples, 0u);
    EXPECT_EQ(u.nonfinite_samples, 0u);
    EXPECT_EQ(u.guided_vertices, 0u);
    guided_vertices += g.guided_vertices;
    texel_samples += uint64_t(gbuffer.texels.size()) * spp;
    testing::add_regions(gbuffer, g, guided);
    testing::add_regions(gbuffer, u, unguided);
    if (cpu_too) {
      const CpuReferenceIntegrator cpu(scene);
      testing::add_regions(gbuffer, cpu.bake(gbuffer, settings(spp, uint64_t(seed) + 2000, GuidingMode::Svo, &octree, mix)),
                  cpu_guided);
    }
  }
  // Guiding must really be on: after the first (unguided) pass most texel vertices sample a field.
  std::printf("[vulkan svo] %s: %.3f guided vertices per texel sample\n", label.c_str(),
              double(guided_vertices) / double(texel_samples));
  EXPECT_GT(double(guided_vertices), 0.5 * double(texel_samples)) << label;
  const double se = testing::expect_regions_agree("vulkan svo", label + " vs unguided", unguided, guided, kZLimit);
  EXPECT_LT(kZLimit * se, kDetectableBias) << "the test could not see a 10 % bias";
  if (cpu_too) testing::expect_regions_agree("vulkan svo", label + " vs CPU svo", cpu_guided, guided, kZLimit);
}

TEST(VulkanSvoGuiding, FurnaceReachesLeOverOneMinusAlbedo) {
  const Vec3 le{1.0f, 0.5f, 0.25f};
  const float rho = 0.5f;
  const Vec3 emission[6] = {le, le, le, le, le, le};
  const testing::AtlasScene box = testing::atlas_box(rho, emission, 8);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(box.scene, 8);
  testing::expect_furnace_closed_form("vulkan svo", le, rho, kSeeds, kZLimit, [&](uint64_t seed) {
    LightmapEstimate e = vk->bake(box.gbuffer, settings(16, seed, GuidingMode::Svo, &octree));
    EXPECT_EQ(e.nonfinite_samples, 0u);
    EXPECT_GT(e.guided_vertices, 0u);
    return e;
  });
}

// A small bright emitter (20 cm, radiance 200, guided share 0.75): NEE's MIS weights against the mixture pdf.
TEST(VulkanSvoGuiding, SmallBrightEmitterAgreesWithUnguided) {
  const Vec3 black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  const testing::AtlasScene box = testing::atlas_box(0.6f, emission, 8, 0.2f, {200, 200, 200});
  expect_guided_agrees("small emitter", box.scene, box.gbuffer, 8, 256, 0.75f, false);
}

TEST(VulkanSvoGuiding, CornellRoomAgreesWithUnguidedAndTheCpu) {
  AtlasSettings atlas;
  atlas.texel_density = 2;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/cornell_room.gltf", "", atlas, diagnostics);
  expect_guided_agrees("cornell_room", p.scene, p.gbuffer, 2, 32, 0.5f, true);
}

TEST(VulkanSvoGuiding, AjarRoomAgreesWithUnguided) {
  AtlasSettings atlas;
  atlas.texel_density = 4;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/ajar_room.gltf", "", atlas, diagnostics);
  expect_guided_agrees("ajar_room", p.scene, p.gbuffer, 4, 64, 0.5f, false);
}

bool identical(const LightmapEstimate& a, const LightmapEstimate& b) {
  if (a.texels.size() != b.texels.size() || a.bounces != b.bounces) return false;
  for (size_t i = 0; i < a.texels.size(); ++i)
    if (std::memcmp(&a.texels[i], &b.texels[i], sizeof(TexelAccumulator)) != 0) return false;
  return true;
}

// Integer counts on the device, deterministic fields on the host: the same seed, the same lightmap
// and the same fields (bins and CDFs).
TEST(VulkanSvoGuiding, BitIdenticalPerSeed) {
  AtlasSettings atlas;
  atlas.texel_density = 2;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/ajar_room.gltf", "", atlas, diagnostics);
  CREATE_VULKAN_OR_SKIP(vk, p.scene);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(p.scene, 2);
  std::vector<std::vector<float>> cdfs;
  std::vector<uint32_t> bins;
  IntegratorSettings s = settings(24, 7, GuidingMode::Svo, &octree);
  s.inspect_svo_guiding = [&](const SvoGuidingFields& f) {
    cdfs.push_back(f.cdf());
    bins.push_back(f.bin_count());
  };
  const LightmapEstimate a = vk->bake(p.gbuffer, s);
  const LightmapEstimate b = vk->bake(p.gbuffer, s);
  ASSERT_EQ(cdfs.size(), 2u);
  EXPECT_GT(bins[0], 0u);
  EXPECT_EQ(bins[0], bins[1]);
  EXPECT_TRUE(cdfs[0] == cdfs[1]);
  EXPECT_TRUE(identical(a, b));
  EXPECT_GT(a.guided_vertices, 0u);
}

}  // namespace
}  // namespace exitance
