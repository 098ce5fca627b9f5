// The Vulkan host around the kernels (runtime/src/vulkan): an integrator that adopts an engine's
// device computes what one on its own device computes, bit for bit, and leaves the device to its
// owner; runtime edits (set_material / set_punctual_light, then update_materials / update_lights)
// equal a fresh integrator on the edited scene, bit for bit, and the CPU reference or the closed
// form; launches are named in the statistics. Validation layers on, every message a failure;
// without a Vulkan device, SKIP.
#include <gtest/gtest.h>

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/analytic_scenes.h"
#include "support/engine_vulkan_device.h"
#include "support/lightmap_comparison.h"
#include "support/textured_scenes.h"
#include "support/validated_vulkan_backend.h"
#include "support/vulkan_device_available.h"

namespace exitance {
namespace {

using testing::AnalyticScene;

using testing::EngineDevice;

void expect_identical(const LightmapEstimate& a, const LightmapEstimate& b, const char* what) {
  ASSERT_EQ(a.texels.size(), b.texels.size()) << what;
  for (size_t i = 0; i < a.texels.size(); ++i) {
    EXPECT_EQ(a.texels[i].samples, b.texels[i].samples) << what << " texel " << i;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(a.texels[i].total[c], b.texels[i].total[c]) << what << " texel " << i;
      EXPECT_EQ(a.texels[i].total_squared[c], b.texels[i].total_squared[c]) << what << " texel " << i;
    }
  }
  EXPECT_EQ(a.bounces, b.bounces) << what;
  EXPECT_EQ(a.rays, b.rays) << what;
}

void expect_identical(const ProbeEstimate& a, const ProbeEstimate& b, const char* what) {
  EXPECT_EQ(a.sh_sum, b.sh_sum) << what;
  EXPECT_EQ(a.samples, b.samples) << what;
  EXPECT_EQ(a.backface_hits, b.backface_hits) << what;
  EXPECT_EQ(a.rays, b.rays) << what;
}

TEST(VulkanExternalDevice, AdoptedDeviceBakesWhatAnOwnDeviceBakes) {
  const AnalyticScene a = testing::white_furnace(0.5f);
  const std::shared_ptr<const LightingScene> scene = make_lighting_scene(a.scene);
  CREATE_VULKAN_OR_SKIP(own, scene, VulkanDeviceOptions{});
  IntegratorSettings settings;
  settings.spp = 64;
  settings.seed = 17;
  const std::vector<Vec3> probes = {{0.5f, 0.5f, 0.5f}, {0.2f, 0.8f, 0.3f}, {0.5f, 0.5f, -0.001f}};
  const LightmapEstimate own_lightmap = own->bake(a.gbuffer, settings);
  const ProbeEstimate own_probes = own->bake_probes(probes, settings);

  EngineDevice engine(own->device().index, vulkan_required_features());
  {
    const auto adopted = VulkanIntegrator::create(scene, engine.options());
    EXPECT_EQ(adopted->device().name, own->device().name);
    EXPECT_NE(adopted->device_description().find("adopted"), std::string::npos);
    expect_identical(adopted->bake(a.gbuffer, settings), own_lightmap, "adopted lightmap");
    expect_identical(adopted->bake_probes(probes, settings), own_probes, "adopted probes");
  }
  // The first integrator is gone and took nothing of the engine's with it: a second one works.
  const auto again = VulkanIntegrator::create(scene, engine.options());
  expect_identical(again->bake(a.gbuffer, settings), own_lightmap, "second adoption");
}

TEST(VulkanExternalDevice, WhatTheBackendNeedsIsChecked) {
  const std::vector<VulkanDeviceInfo> devices = enumerate_vulkan_devices();
  const auto usable = std::find_if(devices.begin(), devices.end(), [](const VulkanDeviceInfo& d) { return d.usable; });
  if (usable == devices.end()) GTEST_SKIP() << "no usable Vulkan device";
  const std::shared_ptr<const LightingScene> scene = make_lighting_scene(testing::white_furnace(0.5f).scene);
  const auto refused = [&](const VulkanDeviceOptions& options) -> std::string {
    try {
      VulkanIntegrator::create(scene, options);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "accepted";
  };
  {
    EngineDevice bare(usable->index, VkPhysicalDeviceFeatures{});  // created without the features the kernels use
    EXPECT_NE(refused(bare.options()).find("shaderInt64"), std::string::npos) << refused(bare.options());
  }
  VkPhysicalDeviceFeatures int64_only{};
  int64_only.shaderInt64 = VK_TRUE;
  EngineDevice half(usable->index, int64_only);
  EXPECT_NE(refused(half.options()).find("shaderFloat64"), std::string::npos);
  EngineDevice engine(usable->index, vulkan_required_features());
  VulkanDeviceOptions old_instance = engine.options();
  old_instance.external_device->api_version = VK_API_VERSION_1_1;
  EXPECT_NE(refused(old_instance).find("Vulkan 1.2"), std::string::npos);
  VulkanDeviceOptions no_queue = engine.options();
  no_queue.external_device->queue_family = 1000;
  EXPECT_NE(refused(no_queue).find("queue family 1000"), std::string::npos);
  VulkanDeviceOptions validation = engine.options();
  validation.validation = true;
  EXPECT_THROW(VulkanIntegrator::create(scene, validation), std::invalid_argument);
}

// A lit box: grey walls, an emitter under the ceiling, a red panel on the left wall. The edit changes
// the emitter's colour, the walls' albedo, and turns the panel into an emitter (the emitter list
// grows, so its buffers do too).
Scene lit_box() {
  Scene scene;
  testing::add_inward_box(scene, {0, 0, 0}, {1, 1, 1}, testing::add_material(scene, {0.5f, 0.5f, 0.5f}));
  testing::add_quad(scene, {0.3f, 0.99f, 0.3f}, {0.4f, 0, 0}, {0, 0, 0.4f}, testing::add_material(scene, {0, 0, 0}, {4, 4, 4}));
  testing::add_quad(scene, {0.01f, 0.2f, 0.2f}, {0, 0.6f, 0}, {0, 0, 0.6f}, testing::add_material(scene, {0.8f, 0.2f, 0.2f}));
  return scene;
}

TEST(VulkanRuntimeEdits, MaterialEditEqualsAFreshIntegratorAndTheReference) {
  const Scene scene = lit_box();
  TexelGBuffer g;
  for (Vec2 p : testing::grid_points(4, 0.1f)) {
    g.texels.push_back(testing::texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));   // floor
    g.texels.push_back(testing::texel_at({p.x, p.y, 0.0f}, {0, 0, 1}));   // back wall
    g.texels.push_back(testing::texel_at({1.0f, p.x, p.y}, {-1, 0, 0}));  // right wall
  }
  const std::shared_ptr<const LightingScene> original = make_lighting_scene(scene);
  CREATE_VULKAN_OR_SKIP(vk, original, VulkanDeviceOptions{});
  IntegratorSettings settings;
  settings.spp = 512;
  settings.seed = 5;
  const LightmapEstimate before = vk->bake(g, settings);

  LightingScene edited = *original;
  Material walls = scene.materials[0], light = scene.materials[1], panel = scene.materials[2];
  walls.base_color = {0.7f, 0.6f, 0.3f};
  light.emission = {1, 2, 3};
  panel.emission = {0.5f, 0.5f, 0.5f};
  set_material(edited, 0, walls);
  set_material(edited, 1, light);
  set_material(edited, 2, panel);
  ASSERT_GT(edited.emitter_count(), original->emitter_count());
  vk->update_materials(edited);
  const LightmapEstimate updated = vk->bake(g, settings);

  CREATE_VULKAN_OR_SKIP(fresh, std::make_shared<const LightingScene>(edited), VulkanDeviceOptions{});
  expect_identical(updated, fresh->bake(g, settings), "updated vs fresh");
  settings.seed = 6;
  const LightmapEstimate reference = CpuReferenceIntegrator(*edited.source).bake(g, settings);
  testing::compare_estimates(updated, reference, 8, "material edit");
  // The edit shows: red light, 4 before and 1 after, far beyond the noise.
  double drop = 0, variance = 0;
  for (size_t i = 0; i < g.texels.size(); ++i)
    drop += before.mean_total(i).x - updated.mean_total(i).x,
        variance += before.variance_of_mean(i).x + updated.variance_of_mean(i).x;
  EXPECT_GT(drop, 20 * std::sqrt(variance));
}

// An emission edit that keeps the emitter list (two emissive materials, one of them brighter): the
// material records (the edited one's power per area) and the CDF are uploaded again, no triangle
// record. Both emitters' area pdfs change, so a stale material record would show as a different bake.
TEST(VulkanRuntimeEdits, EmissionEditKeepingTheEmittersEqualsAFreshIntegrator) {
  Scene scene = lit_box();
  scene.materials[2].emission = {0.5f, 0.5f, 0.5f};
  TexelGBuffer g;
  for (Vec2 p : testing::grid_points(4, 0.1f)) {
    g.texels.push_back(testing::texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));   // floor
    g.texels.push_back(testing::texel_at({1.0f, p.x, p.y}, {-1, 0, 0}));  // right wall, facing the panel
  }
  const std::shared_ptr<const LightingScene> original = make_lighting_scene(scene);
  CREATE_VULKAN_OR_SKIP(vk, original, VulkanDeviceOptions{});
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 5;
  vk->bake(g, settings);
  LightingScene edited = *original;
  Material light = scene.materials[1];
  light.emission = {12, 8, 4};
  set_material(edited, 1, light);
  ASSERT_EQ(edited.emitter_triangles, original->emitter_triangles);
  ASSERT_NE(edited.materials[1].emitter_power.x, original->materials[1].emitter_power.x);
  ASSERT_NE(edited.emitter_inverse_power, original->emitter_inverse_power);
  vk->update_materials(edited);
  const LightmapEstimate updated = vk->bake(g, settings);
  CREATE_VULKAN_OR_SKIP(fresh, std::make_shared<const LightingScene>(edited), VulkanDeviceOptions{});
  expect_identical(updated, fresh->bake(g, settings), "emission edit: updated vs fresh");
}

// Material edits that make an untextured scene textured (its texels and corners are uploaded then)
// and then change a textured scene's alpha mode (only the material records are uploaded).
TEST(VulkanRuntimeEdits, TexturedMaterialEditsEqualAFreshIntegratorAndTheReference) {
  Scene scene = lit_box();
  scene.textures.push_back(testing::checker_texture(4, {0.9f, 0.8f, 0.2f}, {0.1f, 0.3f, 0.7f}, Texture::Wrap::Repeat));
  scene.textures.push_back(testing::two_halves_texture(8, {1, 1, 1}, 0.0f, {0.8f, 0.2f, 0.2f}, 1.0f));
  TexelGBuffer g;
  for (Vec2 p : testing::grid_points(4, 0.1f)) {
    g.texels.push_back(testing::texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));   // floor
    g.texels.push_back(testing::texel_at({1.0f, p.x, p.y}, {-1, 0, 0}));  // right wall, facing the panel
  }
  const std::shared_ptr<const LightingScene> original = make_lighting_scene(scene);
  ASSERT_FALSE(original->textured);
  CREATE_VULKAN_OR_SKIP(vk, original, VulkanDeviceOptions{});
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 5;
  LightingScene edited = *original;
  for (int step = 0; step < 2; ++step) {
    Material walls = scene.materials[0], panel = scene.materials[2];
    walls.base_color_texture.texture = 0;
    walls.base_color_texture.transform.scale = {2.0f, 2.0f};
    panel.base_color_texture.texture = 1;
    panel.alpha_mode = step == 0 ? Material::AlphaMode::Mask : Material::AlphaMode::Blend;
    panel.base_alpha = step == 0 ? 1.0f : 0.5f;  // BLEND: the opaque half passes half the rays
    set_material(edited, 0, walls);
    set_material(edited, 2, panel);
    ASSERT_TRUE(edited.textured);
    vk->update_materials(edited);
    settings.seed = 5;
    const LightmapEstimate updated = vk->bake(g, settings);
    CREATE_VULKAN_OR_SKIP(fresh, std::make_shared<const LightingScene>(edited), VulkanDeviceOptions{});
    expect_identical(updated, fresh->bake(g, settings), step == 0 ? "textured + MASK: updated vs fresh" : "BLEND: updated vs fresh");
    settings.seed = 6;
    testing::compare_estimates(updated, CpuReferenceIntegrator(*edited.source).bake(g, settings), 8,
                               step == 0 ? "textured + MASK edit" : "BLEND edit");
  }
}

TEST(VulkanRuntimeEdits, LightEditEqualsAFreshIntegratorAndTheClosedForm) {
  const AnalyticScene a = testing::point_light_over_plane();
  const std::shared_ptr<const LightingScene> original = make_lighting_scene(a.scene);
  CREATE_VULKAN_OR_SKIP(vk, original, VulkanDeviceOptions{});
  IntegratorSettings settings;
  settings.spp = 4;
  settings.seed = 3;
  vk->bake(a.gbuffer, settings);

  LightingScene edited = *original;
  PunctualLight light = a.scene.lights[0];
  light.position = {-0.5f, 1.5f, 0.4f};
  light.intensity = {4, 1, 2};
  set_punctual_light(edited, 0, light);
  edited.sky = {0.1f, 0.2f, 0.3f};  // the sky is taken by update_lights too
  vk->update_lights(edited);
  const LightmapEstimate updated = vk->bake(a.gbuffer, settings);

  CREATE_VULKAN_OR_SKIP(fresh, std::make_shared<const LightingScene>(edited), VulkanDeviceOptions{});
  expect_identical(updated, fresh->bake(a.gbuffer, settings), "updated vs fresh");
  // Point light I cos / (pi d^2) plus the unoccluded sky: exact on an upward plane.
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i) {
    const Vec3 d = light.position - a.gbuffer.texels[i].position;
    const double cos_over_pi_d2 = d.y / std::sqrt(dot(d, d)) / (kPi * dot(d, d));
    for (int c = 0; c < 3; ++c) {
      const double exact = light.intensity[c] * cos_over_pi_d2 + edited.sky[c];
      EXPECT_NEAR(updated.mean_total(i)[c], exact, 1e-5 * exact) << "texel " << i << " channel " << c;
    }
  }
}

TEST(VulkanRuntimeEdits, UpdatesKeepTheSceneShape) {
  const AnalyticScene a = testing::point_light_over_plane();
  const std::shared_ptr<const LightingScene> original = make_lighting_scene(a.scene);
  CREATE_VULKAN_OR_SKIP(vk, original, VulkanDeviceOptions{});
  LightingScene more_materials = *original;
  more_materials.materials.push_back({});
  EXPECT_THROW(vk->update_materials(more_materials), std::invalid_argument);
  LightingScene more_lights = *original;
  more_lights.punctual_lights.push_back({});
  EXPECT_THROW(vk->update_lights(more_lights), std::invalid_argument);
}

// Moving geometry in place (the emitter quad of lit_box, as a moved instance moves its triangles;
// set_geometry refits the BVH): the update bakes bit for bit what a fresh integrator on the edited
// scene bakes, in both node layouts, and the floor sees the emitter come closer.
TEST(VulkanRuntimeEdits, GeometryEditEqualsAFreshIntegrator) {
  const Scene scene = lit_box();
  TexelGBuffer g;
  for (Vec2 p : testing::grid_points(4, 0.1f)) g.texels.push_back(testing::texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));
  const std::shared_ptr<const LightingScene> original = make_lighting_scene(scene);
  Scene moved = scene;
  for (size_t v = 12 * 3; v < 14 * 3; ++v) moved.positions[v] = moved.positions[v] + Vec3{0.1f, -0.4f, 0.05f};
  LightingScene edited = *original;
  set_geometry(edited, std::make_shared<const Scene>(moved));
  ASSERT_EQ(edited.bvh.nodes.size(), original->bvh.nodes.size());
  for (const VulkanNodeLayout layout : {VulkanNodeLayout::Float, VulkanNodeLayout::Quantized}) {
    SCOPED_TRACE(layout == VulkanNodeLayout::Float ? "float nodes" : "quantized nodes");
    VulkanDeviceOptions options;
    options.node_layout = layout;
    CREATE_VULKAN_OR_SKIP(vk, original, options);
    IntegratorSettings settings;
    settings.spp = 64;
    settings.seed = 9;
    const LightmapEstimate before = vk->bake(g, settings);
    vk->update_geometry(edited);
    const LightmapEstimate updated = vk->bake(g, settings);
    CREATE_VULKAN_OR_SKIP(fresh, std::make_shared<const LightingScene>(edited), options);
    expect_identical(updated, fresh->bake(g, settings), "updated vs fresh");
    // The emitter 0.99 -> 0.59 above the floor: direct light grows about (0.99 / 0.59)^2 ~ 2.8x.
    double rise = 0, variance = 0;
    for (size_t i = 0; i < g.texels.size(); ++i)
      rise += updated.mean_total(i).y - before.mean_total(i).y,
          variance += before.variance_of_mean(i).y + updated.variance_of_mean(i).y;
    EXPECT_GT(rise, 10 * std::sqrt(variance));
  }
  CREATE_VULKAN_OR_SKIP(vk, original, VulkanDeviceOptions{});
  LightingScene fewer = edited;
  fewer.triangles.pop_back();
  EXPECT_THROW(vk->update_geometry(fewer), std::invalid_argument);
  LightingScene other_leaves = edited;
  other_leaves.bvh.leaf_triangles.push_back(0);
  EXPECT_THROW(vk->update_geometry(other_leaves), std::invalid_argument);
}

// The runtime's in-place geometry edit: the scene's emitter quad moved in the source itself,
// refresh_moved_triangles_from_source (the BVH refit over those triangles only) and
// update_moved_geometry (only the moved records, their leaf copies and the changed nodes uploaded)
// bake bit for bit what a fresh integrator on the edited scene bakes, in both node layouts.
TEST(VulkanRuntimeEdits, MovedGeometryUpdateEqualsAFreshIntegrator) {
  TexelGBuffer g;
  for (Vec2 p : testing::grid_points(4, 0.1f)) g.texels.push_back(testing::texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));
  for (const VulkanNodeLayout layout : {VulkanNodeLayout::Float, VulkanNodeLayout::Quantized}) {
    SCOPED_TRACE(layout == VulkanNodeLayout::Float ? "float nodes" : "quantized nodes");
    auto scene = std::make_shared<Scene>(lit_box());
    auto lighting = std::make_shared<LightingScene>(*make_lighting_scene(*scene));
    lighting->source = scene;
    VulkanDeviceOptions options;
    options.node_layout = layout;
    CREATE_VULKAN_OR_SKIP(vk, lighting, options);
    IntegratorSettings settings;
    settings.spp = 64;
    settings.seed = 9;
    const LightmapEstimate before = vk->bake(g, settings);
    const Bvh4Links links = link_bvh4(lighting->bvh, scene->triangle_count());
    const std::vector<uint32_t> moved = {12, 13};
    const std::vector<Vec3> moved_before(scene->positions.begin() + 12 * 3, scene->positions.begin() + 14 * 3);
    // Moved and grown about its centre: its area, hence the emitters' total power, changes (the
    // kernels' GpuParams::emitter_inverse_power must follow, with the CDF, and no other record).
    Vec3 centre{0, 0, 0};
    for (size_t v = 12 * 3; v < 14 * 3; ++v) centre = centre + scene->positions[v] / 6.0f;
    for (size_t v = 12 * 3; v < 14 * 3; ++v)
      scene->positions[v] = centre + (scene->positions[v] - centre) * 1.2f + Vec3{0.1f, -0.4f, 0.05f};
    const float inverse_power_before = lighting->emitter_inverse_power;
    const MovedTrianglesRefresh refreshed =
        refresh_moved_triangles_from_source(*lighting, links, moved, moved_before, scene_world_box(*scene));
    EXPECT_TRUE(refreshed.emitters_changed);
    EXPECT_LT(lighting->emitter_inverse_power, inverse_power_before / 1.3f) << "a larger emitter, more power";
    EXPECT_FALSE(refreshed.bvh_nodes.empty());
    vk->update_moved_geometry(*lighting, links, moved, refreshed.bvh_nodes, refreshed.emitters_changed);
    const LightmapEstimate updated = vk->bake(g, settings);
    CREATE_VULKAN_OR_SKIP(fresh, std::make_shared<const LightingScene>(*lighting), options);
    expect_identical(updated, fresh->bake(g, settings), "updated vs fresh");
    double rise = 0;
    for (size_t i = 0; i < g.texels.size(); ++i) rise += updated.mean_total(i).y - before.mean_total(i).y;
    EXPECT_GT(rise, 0.0) << "the emitter came closer to the floor, and grew";
    EXPECT_THROW(vk->update_moved_geometry(*lighting, links, {13, 12}, refreshed.bvh_nodes, false), std::invalid_argument);
  }
}

// Every launch is named for what it computes, and the statistics are keyed by those names.
TEST(VulkanLaunches, StatisticsAreKeyedByLaunchNames) {
  const AnalyticScene a = testing::white_furnace(0.5f);
  VulkanDeviceOptions options;
  options.collect_stage_statistics = true;
  CREATE_VULKAN_OR_SKIP(vk, make_lighting_scene(a.scene), options);
  IntegratorSettings settings;
  settings.spp = 16;
  const LightmapEstimate e = vk->bake(a.gbuffer, settings);
  std::vector<std::string> names;
  for (const VulkanStageStatistics& s : vk->stage_statistics()) names.push_back(s.stage);
  const auto stage = [&](const std::string& name) -> const VulkanStageStatistics& {
    const auto& all = vk->stage_statistics();
    const auto it = std::find_if(all.begin(), all.end(), [&](const VulkanStageStatistics& s) { return s.stage == name; });
    if (it == all.end()) throw std::runtime_error("no stage '" + name + "'");
    return *it;
  };
  EXPECT_EQ(names.front(), "generate: texel paths into every path slot");
  EXPECT_GT(stage("shade: hits, emission, next-event, continuation").items, 0u);
  EXPECT_EQ(stage("extend: continuation rays (closest hit)").rays,
            stage("rays: primary").rays + stage("rays: bounce").rays);
  EXPECT_EQ(stage("connect: shadow rays (any hit)").rays + stage("extend: continuation rays (closest hit)").rays, e.rays);
  EXPECT_NO_THROW(stage("reduce: samples into texel sums"));
  EXPECT_EQ(stage("rays: primary").rays, uint64_t(a.gbuffer.texels.size()) * settings.spp);
}

// Device failures (issue 31) end a bake with VulkanDeviceFailure, never a hang. A BVH whose root
// lists itself as a child sends every ray round a cycle: the traversal's stack and step bounds end
// each such ray and count it, and the host fails the bake naming the fault.
TEST(VulkanDeviceFailures, CorruptBvhIsACountedFaultNotAHang) {
  const AnalyticScene a = testing::white_furnace(0.5f);
  std::shared_ptr<const LightingScene> good = make_lighting_scene(a.scene);
  auto corrupt = std::make_shared<LightingScene>(*good);
  ASSERT_FALSE(corrupt->bvh.nodes.empty());
  Bvh4Node& root = corrupt->bvh.nodes[0];
  const auto inner = std::find_if(std::begin(root.child), std::end(root.child),
                                  [](uint32_t c) { return c != kBvhEmptyChild; });
  ASSERT_NE(inner, std::end(root.child)) << "the root has no child";
  *inner = 0;  // the root is its own child
  CREATE_VULKAN_OR_SKIP(vk, std::shared_ptr<const LightingScene>(corrupt), VulkanDeviceOptions{});
  IntegratorSettings settings;
  settings.spp = 2;
  try {
    vk->bake(a.gbuffer, settings);
    ADD_FAILURE() << "a bake over a cyclic BVH returned";
  } catch (const VulkanDeviceFailure& e) {
    EXPECT_NE(std::string(e.what()).find("BVH traversals exceeded"), std::string::npos) << e.what();
  }
  // The integrator refuses further work on that device; a fresh one on the intact scene works.
  EXPECT_THROW(vk->bake(a.gbuffer, settings), std::runtime_error);
  CREATE_VULKAN_OR_SKIP(fresh, good, VulkanDeviceOptions{});
  EXPECT_EQ(fresh->bake(a.gbuffer, settings).texels.size(), a.gbuffer.texels.size());
}

// A submission past the fence timeout (here 1 ms: the scene's uploads, the kernels' first
// dispatches or a submission of 4096 wavefront iterations each take longer on any device) is a
// VulkanDeviceFailure, thrown by creation or by the bake, whichever waits first; destroying the
// integrator afterwards returns (it neither waits for the device nor frees what the submission may
// still use; the test's CTest TIMEOUT would catch a wait), and it is never used again.
TEST(VulkanDeviceFailures, TimedOutSubmissionFailsFastAndTeardownReturns) {
  if (!testing::has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const AnalyticScene a = testing::white_furnace(0.5f);
  VulkanDeviceOptions options;
  options.fence_timeout_seconds = 1e-3;
  options.iterations_per_submit = 4096;
  std::unique_ptr<VulkanIntegrator> vk;
  IntegratorSettings settings;
  settings.spp = 4096;
  try {
    vk = VulkanIntegrator::create(make_lighting_scene(a.scene), options);
    vk->bake(a.gbuffer, settings);
    ADD_FAILURE() << "a 4096-spp bake finished within 1 ms per submission";
  } catch (const VulkanDeviceFailure& e) {
    EXPECT_NE(std::string(e.what()).find("did not finish within 0.001 s"), std::string::npos) << e.what();
  }
  if (vk) EXPECT_THROW(vk->bake(a.gbuffer, settings), VulkanDeviceFailure);  // never reused
  vk.reset();  // returns
}

}  // namespace
}  // namespace exitance
