// Sealed texels (bake/raster/sealed_texels.h): texels no light can reach are found, skipped by the
// lighting stage, and filled in the pages from their lit neighbours with valid = 0; texels that a
// light, an opening or a double-sided surface can light are never sealed. Assertions avoid texels
// next to the box walls, where which of two touching surfaces Embree reports depends on its kernels.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "exitance/bake/command/bake_stages.h"
#include "exitance/bake/command/expand_lightmap_estimate.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/raster/geometry_checks.h"
#include "exitance/bake/raster/sealed_texels.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/bake/raster/unocclude.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "support/atlas_box.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

using testing::add_material;
using testing::add_quad;

constexpr float kDensity = 16;  // texels per unit

// A quad of its own instance (own chart: add_quad gives every quad the whole UV square).
void add_named_quad(Scene& scene, const std::string& name, Vec3 c0, Vec3 u, Vec3 v, uint32_t material) {
  add_quad(scene, c0, u, v, material);
  scene.instances.back().name = name;
}

// Axis-aligned box [lo, hi] with outward faces, one instance per face; `with_bottom` false leaves
// the face at y = lo.y out (a box standing on a floor, as the Cornell room's boxes are built).
void add_outward_box(Scene& scene, Vec3 lo, Vec3 hi, uint32_t material, bool with_bottom) {
  const Vec3 d = hi - lo;
  const Vec3 ex{d.x, 0, 0}, ey{0, d.y, 0}, ez{0, 0, d.z};
  if (with_bottom) add_named_quad(scene, "bottom", lo, ex, ez, material);  // normal -y
  add_named_quad(scene, "top", lo + ey, ez, ex, material);                 // normal +y
  add_named_quad(scene, "back", lo, ey, ex, material);                     // z = lo, normal -z
  add_named_quad(scene, "front", lo + ez, ex, ey, material);               // z = hi, normal +z
  add_named_quad(scene, "left", lo, ez, ey, material);                     // x = lo, normal -x
  add_named_quad(scene, "right", lo + ex, ey, ez, material);               // x = hi, normal +x
}

TexelGBuffer raster(const Scene& scene) {
  AtlasSettings atlas;
  atlas.texel_density = kDensity;
  Diagnostics diagnostics;
  const AtlasLayout layout = layout_lightmap_atlas(scene, atlas, "test", diagnostics);
  return rasterize_texel_gbuffer(scene, layout, "test", diagnostics);
}

uint32_t instance_named(const Scene& scene, const std::string& name) {
  for (size_t i = 0; i < scene.instances.size(); ++i)
    if (scene.instances[i].name == name) return uint32_t(i);
  ADD_FAILURE() << "no instance " << name;
  return 0;
}

PunctualLight point_light(Vec3 position) {
  PunctualLight light;
  light.type = PunctualLight::Type::Point;
  light.position = position;
  light.intensity = {5, 5, 5};
  return light;
}

// A 4 x 4 floor at y = 0 with a unit box (no bottom) standing on it at [-0.5, 0.5]², a point light above.
Scene box_on_floor() {
  Scene scene;
  const uint32_t white = add_material(scene, {0.7f, 0.7f, 0.7f});
  add_named_quad(scene, "floor", {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, white);
  add_outward_box(scene, {-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f}, white, false);
  scene.lights.push_back(point_light({0, 3, 0}));
  return scene;
}

// How far inside (> 0) or outside (< 0) the box footprint [-0.5, 0.5]² a floor point lies.
float inside_footprint(Vec3 p) { return 0.5f - std::max(std::fabs(p.x), std::fabs(p.z)); }

TEST(SealedTexels, FloorUnderABoxIsSealedAndTheRestIsNot) {
  const Scene scene = box_on_floor();
  TexelGBuffer gbuffer = raster(scene);
  const EmbreeScene embree(scene);
  unocclude_texels(embree, gbuffer);
  // Traced here, and from the scene checks' closed texels (as bake does): the same answer away from the walls.
  const GeometryCheckReport checks = check_scene_geometry(scene, embree, gbuffer);
  for (const SealedTexels& sealed :
       {find_sealed_texels(scene, embree, gbuffer), find_sealed_texels(scene, embree, gbuffer, &checks.closed_texels)}) {
    const uint32_t floor = instance_named(scene, "floor");
    const float margin = 1.5f / kDensity;
    size_t under = 0;
    for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
      const LiveTexel& t = gbuffer.texels[i];
      if (t.instance != floor) {
        EXPECT_FALSE(sealed.sealed[i]) << "box texel " << i;  // the box's outer faces see the room
        continue;
      }
      const float inside = inside_footprint(t.position);
      if (inside > margin) {
        EXPECT_TRUE(sealed.sealed[i]) << "floor texel under the box at " << t.position.x << ", " << t.position.z;
        ++under;
      } else if (inside < -margin) {
        EXPECT_FALSE(sealed.sealed[i]) << "floor texel beside the box at " << t.position.x << ", " << t.position.z;
      }
    }
    EXPECT_GT(under, 100u);
    EXPECT_GE(sealed.texels, under);
    EXPECT_EQ(sealed.instances, 0u);  // part of the floor is lit
  }
}

TEST(SealedTexels, SkippedTexelsAreFilledFromLitNeighboursAndMarkedInvalid) {
  const Scene scene = box_on_floor();
  TexelGBuffer gbuffer = raster(scene);
  const auto embree = std::make_shared<const EmbreeScene>(scene);
  unocclude_texels(*embree, gbuffer);
  const SealedTexels sealed = find_sealed_texels(scene, *embree, gbuffer);
  ASSERT_GT(sealed.texels, 0u);

  const CpuReferenceIntegrator backend(scene);
  BakeOptions options;
  options.lighting.spp = 4;
  Diagnostics diagnostics;
  const LightmapEstimate estimate = lighting_stage(backend, gbuffer, &sealed, options, diagnostics);
  ASSERT_EQ(estimate.texels.size(), gbuffer.texels.size());
  for (size_t i = 0; i < gbuffer.texels.size(); ++i)
    EXPECT_EQ(estimate.texels[i].samples, sealed.sealed[i] ? 0u : 4u) << "texel " << i;

  const std::vector<formats::LightmapImage> pages =
      assemble_lightmap_pages(gbuffer, estimate, AssemblyOptions{}, sealed.sealed);
  ASSERT_EQ(pages.size(), gbuffer.pages.size());
  for (size_t p = 0; p < pages.size(); ++p) {
    const formats::LightmapImage& page = pages[p];
    ASSERT_TRUE(page.channels.count("valid"));
    EXPECT_EQ(page.channels.at("A"), gbuffer.pages[p].coverage);  // A stays the coverage
    for (const auto& [name, data] : page.channels)
      for (float v : data) ASSERT_TRUE(std::isfinite(v)) << name;
    const std::vector<float>& valid = page.channels.at("valid");
    for (size_t i = 0; i < valid.size(); ++i)
      if (!(gbuffer.pages[p].coverage[i] > 0)) EXPECT_EQ(valid[i], 0.0f) << "gutter texel " << i;
  }
  size_t checked_rings = 0;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    const formats::LightmapImage& page = pages[t.page];
    const int w = page.width, h = page.height;
    const size_t at = size_t(t.y) * size_t(w) + t.x;
    const std::vector<float>& valid = page.channels.at("valid");
    EXPECT_EQ(valid[at], sealed.sealed[i] ? 0.0f : 1.0f);
    if (!sealed.sealed[i]) continue;
    // A sealed texel beside traced ones holds their mean (the first dilation ring), in every channel.
    for (const char* channel : {"R", "G", "B", "direct.R", "indirect.G"}) {
      const std::vector<float>& c = page.channels.at(channel);
      double sum = 0;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = int(t.x) + dx, y = int(t.y) + dy;
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          const size_t j = size_t(y) * size_t(w) + size_t(x);
          if (valid[j] > 0) sum += c[j], ++n;
        }
      if (n == 0) continue;
      EXPECT_NEAR(c[at], sum / n, 1e-5 * (1 + sum / n)) << channel << " at texel " << i;
      ++checked_rings;
    }
  }
  EXPECT_GT(checked_rings, 0u);
}

// A closed single-sided box (outward faces) around a quad: every ray from the quad ends on a back
// face. Dark, the quad is sealed; with a point light inside the box it is not.
Scene closed_box_around_a_quad(bool double_sided, bool light_inside) {
  Scene scene;
  const uint32_t walls = add_material(scene, {0.7f, 0.7f, 0.7f}, {0, 0, 0}, double_sided);
  const uint32_t white = add_material(scene, {0.7f, 0.7f, 0.7f});
  add_outward_box(scene, {-1, -1, -1}, {1, 1, 1}, walls, true);
  add_named_quad(scene, "inner", {-0.5f, -0.5f, -0.5f}, {0, 0, 1}, {1, 0, 0}, white);  // normal +y
  if (light_inside) scene.lights.push_back(point_light({0, 0.5f, 0}));
  return scene;
}

size_t sealed_of_instance(const Scene& scene, const TexelGBuffer& gbuffer, const SealedTexels& sealed,
                          const std::string& name, size_t* live = nullptr) {
  const uint32_t instance = instance_named(scene, name);
  size_t count = 0, texels = 0;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i)
    if (gbuffer.texels[i].instance == instance) count += sealed.sealed[i], ++texels;
  if (live) *live = texels;
  return count;
}

TEST(SealedTexels, DarkClosedSingleSidedBoxSealsWhatIsInside) {
  const Scene scene = closed_box_around_a_quad(false, false);
  const TexelGBuffer gbuffer = raster(scene);
  const SealedTexels sealed = find_sealed_texels(scene, EmbreeScene(scene), gbuffer);
  size_t live = 0;
  EXPECT_EQ(sealed_of_instance(scene, gbuffer, sealed, "inner", &live), live);
  EXPECT_GT(live, 0u);
  EXPECT_EQ(sealed.texels, live);  // the box's outer faces see open space
  EXPECT_EQ(sealed.instances, 1u);
}

TEST(SealedTexels, PointLightInsideAClosedBoxKeepsItsTexels) {
  const Scene scene = closed_box_around_a_quad(false, true);
  const TexelGBuffer gbuffer = raster(scene);
  const SealedTexels sealed = find_sealed_texels(scene, EmbreeScene(scene), gbuffer);
  EXPECT_EQ(sealed_of_instance(scene, gbuffer, sealed, "inner"), 0u);
  EXPECT_GT(sealed.candidates, 0u);  // every ray hit a back face: only the light keeps them
  EXPECT_EQ(sealed.texels, 0u);
}

TEST(SealedTexels, DoubleSidedEnclosureIsNotSealed) {
  const Scene scene = closed_box_around_a_quad(true, false);
  const TexelGBuffer gbuffer = raster(scene);
  const SealedTexels sealed = find_sealed_texels(scene, EmbreeScene(scene), gbuffer);
  EXPECT_EQ(sealed.texels, 0u);
  EXPECT_EQ(sealed.candidates, 0u);
}

TEST(SealedTexels, OpenScenesHaveNone) {
  {  // a closed room seen from inside: front faces everywhere
    const Vec3 emission[6] = {};
    const testing::AtlasScene room = testing::atlas_box(0.5f, emission, 8);
    const SealedTexels sealed = find_sealed_texels(room.scene, EmbreeScene(room.scene), room.gbuffer);
    EXPECT_FALSE(room.gbuffer.texels.empty());
    EXPECT_EQ(sealed.texels, 0u);
  }
  {  // a floor under the sky with a box on it: only the rays the box blocks end on it
    Scene scene;
    const uint32_t white = add_material(scene, {0.7f, 0.7f, 0.7f});
    add_named_quad(scene, "floor", {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, white);
    add_outward_box(scene, {-0.5f, 0.2f, -0.5f}, {0.5f, 1.2f, 0.5f}, white, true);  // lifted off the floor
    const TexelGBuffer gbuffer = raster(scene);
    const SealedTexels sealed = find_sealed_texels(scene, EmbreeScene(scene), gbuffer);
    EXPECT_EQ(sealed.texels, 0u);
    EXPECT_EQ(sealed.instances, 0u);
  }
}

TEST(SealedTexels, ExpansionPutsTracedTexelsBackInPlace) {
  LightmapEstimate traced;
  traced.texels.resize(2);
  traced.texels[0].samples = 3, traced.texels[0].total[0] = 1;
  traced.texels[1].samples = 5, traced.texels[1].total[2] = 2;
  traced.recorded_bounces = 2;
  traced.bounces = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};  // [bounce][texel][rgb]
  traced.rays = 42;
  const std::vector<uint8_t> skipped = {1, 0, 1, 0};
  const LightmapEstimate full = expand_lightmap_estimate(traced, skipped);
  ASSERT_EQ(full.texels.size(), 4u);
  EXPECT_EQ(full.texels[0].samples, 0u);
  EXPECT_EQ(full.texels[1].samples, 3u);
  EXPECT_EQ(full.texels[2].samples, 0u);
  EXPECT_EQ(full.texels[3].samples, 5u);
  EXPECT_EQ(full.mean_total(0).x, 0.0f);  // no NaN for a texel with no samples
  EXPECT_EQ(full.rays, 42u);
  const std::vector<double> bounces = {0, 0, 0, 1, 2, 3, 0, 0, 0, 4, 5, 6, 0, 0, 0, 7, 8, 9, 0, 0, 0, 10, 11, 12};
  EXPECT_EQ(full.bounces, bounces);
  EXPECT_THROW(expand_lightmap_estimate(traced, {0, 0, 0}), std::logic_error);
}

}  // namespace
}  // namespace exitance
