// SVO path guiding (--guiding svo, issue 11) on the CPU backend: the cone-footprint level formula;
// forced on, the guided path tracer converges to the closed form in a white furnace and to the
// unguided path tracer per region (instance) on a box lit by a small bright emitter (NEE + MIS
// against the mixture pdf), the Cornell room, the courtyard (sky) and ajar_room; no NaN/Inf; a
// one-emitter scene's field peaks toward the emitter; PARTITION-S's bins follow c_ray and l_min;
// an octree holding exitance guides the first pass; results bit-identical per seed and across
// thread counts.
//
// Statistics as guided_path_test.cpp: standard errors from kSeeds independent seeds, kZLimit = 5
// (two-sided p ~ 1.3e-4 under Student's t with 15 dof per region), and each test checks its power:
// a 10 % bias in the median region must exceed kZLimit standard errors.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/core/svo_guiding_fields.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "support/atlas_box.h"
#include "support/identical_estimates.h"
#include "support/independent_estimates.h"
#include "support/guiding_octree.h"
#include "support/region_and_furnace_checks.h"

namespace exitance {
namespace {

constexpr double kZLimit = 5.0;
constexpr int kSeeds = 16;
constexpr double kDetectableBias = 0.10;
constexpr double kPi = 3.141592653589793;

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

// Guided against unguided, per region, over kSeeds independent seeds each. Returns the median over
// regions of the relative standard error of the difference.
double expect_regions_agree(const std::string& label, const Scene& scene, const TexelGBuffer& gbuffer, float density,
                            uint32_t spp, float mix = 0.5f, bool texels = true) {
  const CpuReferenceIntegrator integrator(scene);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(scene, density);
  std::map<uint32_t, std::vector<double>> guided, unguided;
  uint64_t guided_vertices = 0, vertices_possible = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    IntegratorSettings guided_settings = settings(spp, uint64_t(seed), GuidingMode::Svo, &octree, mix);
    guided_settings.guiding_svo_texels = texels;
    const LightmapEstimate g = integrator.bake(gbuffer, guided_settings);
    const LightmapEstimate u = integrator.bake(gbuffer, settings(spp, uint64_t(seed) + 1000, GuidingMode::Off, nullptr));
    EXPECT_EQ(g.nonfinite_samples, 0u);
    EXPECT_EQ(u.nonfinite_samples, 0u);
    guided_vertices += g.guided_vertices;
    vertices_possible += uint64_t(gbuffer.texels.size()) * spp;
    for (auto& [region, m] : testing::region_means(gbuffer, testing::luminance_means(g))) guided[region].push_back(m);
    for (auto& [region, m] : testing::region_means(gbuffer, testing::luminance_means(u))) unguided[region].push_back(m);
  }
  // Guiding must really be on: after the first pass most texel vertices sample the mixture (without
  // texels, some later vertices do).
  if (texels) EXPECT_GT(double(guided_vertices), 0.5 * double(vertices_possible)) << label;
  else EXPECT_GT(guided_vertices, 0u) << label;
  return testing::expect_region_means_agree("svo guided", label, guided, unguided, kZLimit);
}

// The cone's half-angle solves Omega = 2 pi (1 - cos theta); the level's voxel edge size / 2^level
// is the smallest power-of-two fraction of the cube not below the footprint diameter 2 r tan theta.
TEST(SvoGuiding, ConeFootprintLevel) {
  for (double theta : {0.01, 0.1, 0.5, 1.0, 1.5}) {
    const double omega = 2 * kPi * (1 - std::cos(theta));
    EXPECT_NEAR(svo_guide_cone_half_angle(omega), theta, 1e-9) << theta;
  }
  EXPECT_NEAR(svo_guide_cone_half_angle(2 * kPi), kPi / 2, 1e-12);  // the hemisphere
  // A 16 x 16 hemisphere bin: Omega = 2 pi / 256, theta = acos(1 - 1/256) ~ sqrt(2) / 16 (small cone).
  const double bin = 2 * kPi / 256;
  EXPECT_NEAR(svo_guide_cone_half_angle(bin), std::acos(1.0 - 1.0 / 256), 1e-12);
  EXPECT_NEAR(svo_guide_cone_half_angle(bin), std::sqrt(2.0) / 16, 2e-4);
  // Cube 16, depth 10, r = 1: R = tan(0.08841) = 0.08864, 16 / (2R) = 90.25, log2 = 6.50 -> level 6.
  EXPECT_EQ(svo_guide_cone_level(bin, 1.0, 16.0, 10), 6u);
  // Seed 000's public code used R = 4 r / N = 0.25 (a solid angle as a plane angle): level 5, 2.8x too coarse.
  EXPECT_EQ(uint32_t(std::floor(std::log2(16.0 / (2 * 4.0 / 16)))), 5u);
  // Doubling the distance doubles the footprint: one level coarser; never below 0 nor above depth.
  for (double r : {0.01, 0.1, 1.0, 3.0}) {
    const uint32_t near_level = svo_guide_cone_level(bin, r, 16.0, 20), far_level = svo_guide_cone_level(bin, 2 * r, 16.0, 20);
    EXPECT_EQ(near_level, far_level + 1) << r;
    const double edge = 16.0 / std::ldexp(1.0, int(near_level));
    const double diameter = 2 * r * std::tan(svo_guide_cone_half_angle(bin));
    EXPECT_GE(edge * (1 + 1e-9), diameter) << r;
    EXPECT_LT(edge, 2 * diameter) << r;
  }
  EXPECT_EQ(svo_guide_cone_level(bin, 1e-9, 16.0, 8), 8u);
  EXPECT_EQ(svo_guide_cone_level(bin, 1e9, 16.0, 8), 0u);
  EXPECT_EQ(svo_guide_cone_level(2 * kPi, 1.0, 16.0, 8), 0u);
}

TEST(SvoGuiding, FurnaceReachesLeOverOneMinusAlbedo) {
  const Vec3 le{1.0f, 0.5f, 0.25f};
  const float rho = 0.5f;
  const Vec3 emission[6] = {le, le, le, le, le, le};
  const testing::AtlasScene box = testing::atlas_box(rho, emission, 8);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(box.scene, 8);
  const CpuReferenceIntegrator integrator(box.scene);
  testing::expect_furnace_closed_form("svo guided", le, rho, kSeeds, kZLimit, [&](uint64_t seed) {
    LightmapEstimate e = integrator.bake(box.gbuffer, settings(16, seed, GuidingMode::Svo, &octree));
    EXPECT_EQ(e.nonfinite_samples, 0u);
    EXPECT_GT(e.guided_vertices, 0u);
    return e;
  });
}

// The small bright emitter of guided_path_test.cpp (20 cm, radiance 200, 4 % of the ceiling): the
// guided continuations find it often, so NEE's MIS weight against the mixture pdf decides the result.
TEST(SvoGuiding, SmallBrightEmitterAgreesWithUnguided) {
  const Vec3 black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  const testing::AtlasScene box = testing::atlas_box(0.6f, emission, 8, 0.2f, {200, 200, 200});
  const double se = expect_regions_agree("small emitter", box.scene, box.gbuffer, 8, 256, 0.75f);
  EXPECT_LT(kZLimit * se, kDetectableBias) << "the test could not see a 10 % bias";
}

double scene_agrees(const char* name, float density, uint32_t spp, bool texels = true) {
  AtlasSettings atlas;
  atlas.texel_density = density;
  Diagnostics diagnostics;
  const PreparedScene p =
      prepare_scene_for_lighting(std::string(EXITANCE_SAMPLE_DIR "/") + name + ".gltf", "", atlas, diagnostics);
  return expect_regions_agree(name, p.scene, p.gbuffer, density, spp, 0.5f, texels);
}

TEST(SvoGuiding, CornellRoomAgreesWithUnguided) {
  EXPECT_LT(kZLimit * scene_agrees("cornell_room", 2, 32), kDetectableBias) << "the test could not see a 10 % bias";
}

TEST(SvoGuiding, CourtyardAgreesWithUnguided) {
  EXPECT_LT(kZLimit * scene_agrees("courtyard", 0.5f, 32), kDetectableBias) << "the test could not see a 10 % bias";
}

// Guiding from bounce 1 only (guiding_svo_texels = false): texels sample cosine, later vertices guided.
TEST(SvoGuiding, CourtyardFromBounceOneAgreesWithUnguided) {
  EXPECT_LT(kZLimit * scene_agrees("courtyard", 0.5f, 32, false), kDetectableBias) << "the test could not see a 10 % bias";
}

TEST(SvoGuiding, AjarRoomAgreesWithUnguided) {
  EXPECT_LT(kZLimit * scene_agrees("ajar_room", 4, 64), kDetectableBias) << "the test could not see a 10 % bias";
}

// A dark box (albedo 0.05) lit by one small emitter under the ceiling's centre: a floor record's
// brightest bin, traced from its capture origin, reaches the ceiling plane on or next to the
// emitter (within one bin's footprint: the field is blurred by one bin).
TEST(SvoGuiding, BrightestBinPointsAtTheEmitter) {
  const Vec3 black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  const testing::AtlasScene box = testing::atlas_box(0.05f, emission, 8, 0.2f, {200, 200, 200});
  const formats::SparseVoxelOctree octree = testing::guiding_octree(box.scene, 8);
  IntegratorSettings s = settings(8, 3, GuidingMode::Svo, &octree);
  int floor_records = 0;
  s.inspect_svo_guiding = [&](const SvoGuidingFields& fields) {
    EXPECT_GE(fields.rebuilds(), 3u);
    for (uint32_t r = 0; r < fields.record_count(); ++r) {
      if (fields.record_class(r) != 2) continue;  // +y: the floor
      const Vec3 o = fields.capture_origin(r);
      if (!(o.y < 0.01f) || o.x < 0.2f || o.x > 0.8f || o.z < 0.2f || o.z > 0.8f) continue;  // floor, under the light
      const float* f = fields.field(r);
      const uint32_t peak = uint32_t(std::max_element(f, f + kGuideBins) - f);
      const Vec3 d = guide_from_class_local(2, guide_bin_point(peak, 0.5f, 0.5f));
      ASSERT_GT(d.y, 0.0f);
      const float t = (0.999f - o.y) / d.y;
      const Vec3 at = o + d * t;
      // One bin is ~0.09 rad wide; at ~1 m that is ~0.1: the emitter square [0.4, 0.6] grown by 0.1.
      EXPECT_NEAR(at.x, 0.5f, 0.2f) << "record " << r;
      EXPECT_NEAR(at.z, 0.5f, 0.2f) << "record " << r;
      ++floor_records;
    }
  };
  const LightmapEstimate e = CpuReferenceIntegrator(box.scene).bake(box.gbuffer, s);
  EXPECT_EQ(e.nonfinite_samples, 0u);
  EXPECT_GT(floor_records, 0);
}

// PARTITION-S: with an unreachable c_ray every bin is at l_min; with a tiny one bins reach deeper
// levels; every vertex's bin is an ancestor-or-self at or below l_min.
TEST(SvoGuiding, BinsFollowCRayAndLMin) {
  AtlasSettings atlas;
  atlas.texel_density = 2;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/cornell_room.gltf", "", atlas, diagnostics);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(p.scene, 2);
  ASSERT_GE(octree.depth, 4u);
  const uint32_t l_min = octree.depth - 3;
  auto levels = [&](double c_ray) {
    std::vector<uint32_t> count(octree.depth + 1, 0);
    IntegratorSettings s = settings(4, 1, GuidingMode::Svo, &octree);
    s.guiding_svo_c_ray = c_ray;
    s.inspect_svo_guiding = [&](const SvoGuidingFields& fields) {
      for (uint32_t b = 0; b < fields.bin_count(); ++b) ++count[octree.nodes[fields.bin_node(b)].level];
      for (size_t node = 0; node < octree.nodes.size(); ++node) {
        const uint32_t bin = fields.node_bin()[node];
        if (octree.nodes[node].level < l_min) {
          EXPECT_EQ(bin, SvoGuidingFields::kNoBin);
          continue;
        }
        if (bin == SvoGuidingFields::kNoBin) continue;
        uint32_t a = uint32_t(node);  // the bin's node is an ancestor-or-self
        while (a != fields.bin_node(bin) && a != 0) a = octree.nodes[a].parent;
        EXPECT_EQ(a, fields.bin_node(bin)) << node;
      }
    };
    CpuReferenceIntegrator(p.scene).bake(p.gbuffer, s);
    return count;
  };
  const std::vector<uint32_t> coarse = levels(1e12), fine = levels(1e-6);
  uint32_t coarse_total = 0, deeper = 0;
  for (uint32_t l = 0; l <= octree.depth; ++l) {
    if (l != l_min) {
      EXPECT_EQ(coarse[l], 0u) << l;
    }
    coarse_total += coarse[l];
    if (l > l_min) deeper += fine[l];
  }
  EXPECT_GT(coarse_total, 0u);
  EXPECT_GT(deeper, coarse_total);
}

bool identical(const LightmapEstimate& a, const LightmapEstimate& b) { return testing::identical_texel_sums(a, b); }

TEST(SvoGuiding, BitIdenticalPerSeedAndThreadCount) {
  AtlasSettings atlas;
  atlas.texel_density = 4;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/ajar_room.gltf", "", atlas, diagnostics);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(p.scene, 4);
  const CpuReferenceIntegrator integrator(p.scene);
  const LightmapEstimate a = integrator.bake(p.gbuffer, settings(24, 7, GuidingMode::Svo, &octree));
  const LightmapEstimate b = integrator.bake(p.gbuffer, settings(24, 7, GuidingMode::Svo, &octree));
  EXPECT_GT(a.guided_vertices, 0u);
  EXPECT_TRUE(identical(a, b)) << "two runs with one seed differ";
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const LightmapEstimate c = integrator.bake(p.gbuffer, settings(24, 7, GuidingMode::Svo, &octree));
    EXPECT_TRUE(identical(a, c)) << "one thread and all threads differ";
  }
  const LightmapEstimate other = integrator.bake(p.gbuffer, settings(24, 8, GuidingMode::Svo, &octree));
  EXPECT_FALSE(identical(a, other)) << "the seed must matter";
}

// An octree that already holds exitance (an earlier bake's svo.bin) seeds the guide: its fields are
// built before the first pass, so even a 1-spp bake samples guided; a fresh octree's first pass is
// unguided.
TEST(SvoGuiding, OctreeWithExitanceGuidesTheFirstPass) {
  const Vec3 le{1, 1, 1};
  const Vec3 emission[6] = {le, le, le, le, le, le};
  const testing::AtlasScene box = testing::atlas_box(0.5f, emission, 8);
  formats::SparseVoxelOctree octree = testing::guiding_octree(box.scene, 8);
  const CpuReferenceIntegrator integrator(box.scene);
  EXPECT_EQ(integrator.bake(box.gbuffer, settings(1, 1, GuidingMode::Svo, &octree)).guided_vertices, 0u);
  fill_svo_exitance(octree, box.scene, box.gbuffer, integrator.bake(box.gbuffer, settings(4, 2, GuidingMode::Off, nullptr)));
  uint32_t seeded_rebuilds = 0;
  IntegratorSettings s = settings(1, 1, GuidingMode::Svo, &octree);
  s.inspect_svo_guiding = [&](const SvoGuidingFields& fields) { seeded_rebuilds = fields.rebuilds(); };
  const LightmapEstimate e = integrator.bake(box.gbuffer, s);
  EXPECT_GT(e.guided_vertices, 0u);
  EXPECT_EQ(seeded_rebuilds, 2u);  // before the first pass, and after it
  EXPECT_EQ(e.nonfinite_samples, 0u);
}

TEST(SvoGuiding, RefusedWithoutOctreeOrInBouncesMode) {
  const Vec3 le{1, 1, 1};
  const Vec3 emission[6] = {le, le, le, le, le, le};
  const testing::AtlasScene box = testing::atlas_box(0.5f, emission, 4);
  const formats::SparseVoxelOctree octree = testing::guiding_octree(box.scene, 4);
  const CpuReferenceIntegrator integrator(box.scene);
  EXPECT_THROW(integrator.bake(box.gbuffer, settings(4, 1, GuidingMode::Svo, nullptr)), std::invalid_argument);
  IntegratorSettings bounces = settings(4, 1, GuidingMode::Svo, &octree);
  bounces.integrator = IntegratorMode::Bounces;
  EXPECT_THROW(integrator.bake(box.gbuffer, bounces), std::invalid_argument);
}

}  // namespace
}  // namespace exitance
