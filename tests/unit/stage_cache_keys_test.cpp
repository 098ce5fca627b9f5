// The per-stage cache keys (bake/cache/stage_cache_keys.h): each key changes when one of the inputs
// its stage reads changes (a key that misses one would reuse a wrong product), and stays when only
// lighting inputs change (light intensity, emission strength, sky, samples), which is the point.
#include <gtest/gtest.h>

#include <functional>
#include <set>
#include <string>

#include "exitance/bake/cache/stage_cache_keys.h"

namespace exitance {
namespace {

// Two triangles (a quad) with one material, one instance and one point light.
Scene small_scene() {
  Scene s;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  s.normals.assign(6, {0, 1, 0});
  s.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  s.lightmap_uv = s.uv0;
  s.triangle_material = {0, 0};
  s.triangle_instance = {0, 0};
  s.materials.push_back(Material{});
  s.materials[0].emission = {1, 1, 1};
  Texture t;
  t.width = t.height = 1;
  t.rgb = {1, 1, 1};
  s.textures.push_back(t);
  Instance i;
  i.node = 0, i.mesh = 0, i.triangle_count = 2;
  s.instances.push_back(i);
  PunctualLight l;
  l.position = {0.5f, 1, 0.5f};
  s.lights.push_back(l);
  return s;
}

BakeOptions small_options() {
  BakeOptions o;
  o.input = "scene.gltf";
  return o;
}

using Keys = StageCacheKeys;
const std::vector<std::pair<const char*, std::string Keys::*>> kStages = {
    {"layout", &Keys::layout},       {"gbuffer", &Keys::gbuffer},   {"checks", &Keys::checks},
    {"sealed_texels", &Keys::sealed_texels}, {"voxelize", &Keys::voxelize}, {"probe_placement", &Keys::probe_placement}};

struct Change {
  const char* what;
  std::function<void(Scene&, BakeOptions&, std::string&)> apply;
  std::set<std::string> changed;  // the stages whose key must change; every other key must stay
};

const std::set<std::string> kAll = {"layout", "gbuffer", "checks", "sealed_texels", "voxelize", "probe_placement"};
const std::set<std::string> kAfterGBuffer = {"gbuffer", "checks", "sealed_texels"};
const std::set<std::string> kVisibility = {"gbuffer", "checks", "sealed_texels", "probe_placement"};

TEST(StageCacheKeys, EachKeyChangesWithWhatItsStageReadsAndOnlyWithThat) {
  const std::vector<Change> changes = {
      {"a vertex position", [](Scene& s, BakeOptions&, std::string&) { s.positions[2].y = 0.1f; }, kAll},
      {"an instance transform", [](Scene& s, BakeOptions&, std::string&) { s.instances[0].world[12] = 1; }, kAll},
      {"the program", [](Scene&, BakeOptions&, std::string& p) { p = "another build"; }, kAll},
      {"the input path (warnings name it)", [](Scene&, BakeOptions& o, std::string&) { o.input = "b.gltf"; }, kAll},
      {"a lightmap UV", [](Scene& s, BakeOptions&, std::string&) { s.lightmap_uv[1].x = 0.9f; }, kAll},
      {"--texel-density", [](Scene&, BakeOptions& o, std::string&) { o.atlas.texel_density = 9; }, kAll},
      {"--max-page", [](Scene&, BakeOptions& o, std::string&) { o.atlas.max_page = 512; }, kAll},
      {"a shading normal", [](Scene& s, BakeOptions&, std::string&) { s.normals[0] = {0, 0.8f, 0.6f}; },
       kAfterGBuffer},
      {"base colour", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].base_color = {0.5f, 1, 1}; },
       kAfterGBuffer},
      {"metallic", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].metallic = 0.5f; }, kAfterGBuffer},
      {"a vertex colour", [](Scene& s, BakeOptions&, std::string&) { s.vertex_color.assign(6, {1, 0.5f, 1}); },
       kAfterGBuffer},
      {"a texture texel", [](Scene& s, BakeOptions&, std::string&) { s.textures[0].rgb[0] = 0.5f; }, kVisibility},
      {"the base colour texture", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].base_color_texture.texture = 0; },
       kVisibility},
      {"TEXCOORD_0", [](Scene& s, BakeOptions&, std::string&) { s.uv0[0].x = 0.5f; }, kVisibility},
      {"doubleSided", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].double_sided = true; }, kVisibility},
      {"alphaMode", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].alpha_mode = Material::AlphaMode::Mask; },
       kVisibility},
      {"alpha cutoff", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].alpha_cutoff = 0.25f; }, kVisibility},
      {"base alpha", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].base_alpha = 0.5f; }, kVisibility},
      {"a vertex alpha", [](Scene& s, BakeOptions&, std::string&) { s.vertex_alpha.assign(6, 0.5f); }, kVisibility},
      {"a light position", [](Scene& s, BakeOptions&, std::string&) { s.lights[0].position.y = 2; },
       {"checks", "sealed_texels"}},
      {"a light type", [](Scene& s, BakeOptions&, std::string&) { s.lights[0].type = PunctualLight::Type::Directional; },
       {"checks", "sealed_texels"}},
      {"a light direction", [](Scene& s, BakeOptions&, std::string&) { s.lights[0].direction = {0, -1, 0}; },
       {"checks", "sealed_texels"}},
      {"a new light", [](Scene& s, BakeOptions&, std::string&) { s.lights.push_back(s.lights[0]); },
       {"checks", "sealed_texels"}},
      {"a light name (the enclosed-light warning)", [](Scene& s, BakeOptions&, std::string&) { s.lights[0].name = "x"; },
       {"checks", "sealed_texels"}},
      {"emission off (no emitters to check)", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].emission = {}; },
       {"checks"}},
      {"--voxel-resolution", [](Scene&, BakeOptions& o, std::string&) { o.voxel_resolution = 64; },
       {"voxelize", "probe_placement"}},
      {"--probes spacing", [](Scene&, BakeOptions& o, std::string&) { o.probe_spacing = 0.5f; }, {"probe_placement"}},
      {"no octree (--voxel-resolution none)", [](Scene&, BakeOptions& o, std::string&) { o.svo_enabled = false; },
       {"probe_placement"}},
      // Lighting-only inputs: every offline product is reused.
      {"light intensity", [](Scene& s, BakeOptions&, std::string&) { s.lights[0].intensity = {5, 4, 3}; }, {}},
      {"spot cone", [](Scene& s, BakeOptions&, std::string&) { s.lights[0].cos_outer = 0.5f; }, {}},
      {"emission strength", [](Scene& s, BakeOptions&, std::string&) { s.materials[0].emission = {3, 2, 1}; }, {}},
      {"the sky", [](Scene& s, BakeOptions& o, std::string&) { s.sky.constant = {1, 1, 1}, o.sky = "1,1,1"; }, {}},
      {"samples and seed", [](Scene&, BakeOptions& o, std::string&) { o.lighting.spp = 99, o.lighting.seed = 3; }, {}},
      {"probe samples", [](Scene&, BakeOptions& o, std::string&) { o.probe_spp = 99; }, {}},
  };
  const Keys base = stage_cache_keys(small_scene(), small_options(), "program");
  for (const Change& change : changes) {
    SCOPED_TRACE(change.what);
    Scene scene = small_scene();
    BakeOptions options = small_options();
    std::string program = "program";
    change.apply(scene, options, program);
    const Keys changed = stage_cache_keys(scene, options, program);
    for (const auto& [stage, key] : kStages) {
      if (change.changed.count(stage))
        EXPECT_NE(changed.*key, base.*key) << stage << " must be computed again";
      else
        EXPECT_EQ(changed.*key, base.*key) << stage << " should be reused";
    }
  }
}

TEST(StageCacheKeys, KeysAreDistinctPerStageAndStable) {
  const Keys a = stage_cache_keys(small_scene(), small_options(), "program");
  const Keys b = stage_cache_keys(small_scene(), small_options(), "program");
  std::set<std::string> distinct;
  for (const auto& [stage, key] : kStages) {
    EXPECT_EQ(a.*key, b.*key) << stage;
    EXPECT_EQ((a.*key).size(), 64u) << stage;
    distinct.insert(a.*key);
  }
  EXPECT_EQ(distinct.size(), kStages.size());
}

}  // namespace
}  // namespace exitance
