// Runtime scene edits (runtime/include/exitance/runtime/refresh/scene_edits.h) on a small glTF
// taken through the offline stage and scene.bin: parse errors as one line naming the edit and the
// field; bad edits leave the scene bit for bit as it was; each edit type's effect; node edits
// against importing the glTF with the node changed; the BVH refit; set_geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/runtime/core/bvh4_refit.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/node_transform.h"
#include "exitance/runtime/refresh/scene_edits.h"
#include "exitance/runtime/refresh/texels_near_change.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/world_box.h"

#include "support/base64.h"

namespace exitance {
namespace {

using json = nlohmann::json;
constexpr double kHalfUlp = 1.0 / (1 << 24);  // float's unit roundoff 2^-24

using test::base64;

// A unit quad (two triangles, +Z normals, TEXCOORD_1 = xy) used by every mesh node; a spot lamp
// and a directional sun; a matrix node ("Group") above an emissive panel; two nodes named "Twin".
json scene_document() {
  std::vector<float> values = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0};  // POSITION
  for (int i = 0; i < 6; ++i) values.insert(values.end(), {0, 0, 1});                  // NORMAL
  values.insert(values.end(), {0.05f, 0.05f, 0.95f, 0.05f, 0.95f, 0.95f, 0.05f, 0.05f, 0.95f, 0.95f, 0.05f, 0.95f});
  std::vector<unsigned char> bytes(values.size() * 4);
  std::memcpy(bytes.data(), values.data(), bytes.size());
  json d = json::parse(R"({
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
      {"type": "spot", "name": "Lamp", "color": [1, 0.9, 0.8], "intensity": 5,
       "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
      {"type": "directional", "name": "Sun", "intensity": 2}]}},
    "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [
      {"name": "Root", "children": [1, 2, 3, 5, 6, 7]},
      {"name": "Box", "mesh": 0, "translation": [1, 0, 0.5], "rotation": [0, 0.19866933, 0, 0.98006658]},
      {"name": "sun", "rotation": [-0.38268343, 0, 0, 0.92387953], "extensions": {"KHR_lights_punctual": {"light": 1}}},
      {"name": "Group", "matrix": [0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 2, 0, 1], "children": [4]},
      {"name": "Panel", "mesh": 1, "translation": [0.25, 0, 0]},
      {"name": "Twin", "mesh": 0, "translation": [3, 0, 0]},
      {"name": "Twin", "mesh": 0, "translation": [-3, 0, 0]},
      {"name": "LampNode", "translation": [0, 3, 0], "rotation": [-0.70710678, 0, 0, 0.70710678],
       "extensions": {"KHR_lights_punctual": {"light": 0}}}],
    "materials": [{"name": "Grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}},
                  {"name": "Panel", "emissiveFactor": [1, 0.5, 0.25]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_1": 2}, "material": 0}]},
               {"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_1": 2}, "material": 1}]}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
      {"bufferView": 0, "byteOffset": 72, "componentType": 5126, "count": 6, "type": "VEC3"},
      {"bufferView": 1, "componentType": 5126, "count": 6, "type": "VEC2"}],
    "bufferViews": [{"buffer": 0, "byteLength": 144}, {"buffer": 0, "byteOffset": 144, "byteLength": 48}],
    "buffers": [{"byteLength": 192}]
  })");
  d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bytes);
  return d;
}

Scene import_document(const json& d) {
  static int counter = 0;
  const auto path = std::filesystem::temp_directory_path() /
                    ("scene_edits_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".gltf");
  std::ofstream(path) << d.dump();
  Diagnostics diagnostics;
  Scene scene = import_gltf(path.string(), ImportOptions{}, diagnostics);
  std::filesystem::remove(path);
  return scene;
}

AtlasLayout layout_of(const Scene& scene) {
  Diagnostics diagnostics;
  AtlasSettings settings;
  settings.texel_density = 8;
  return layout_lightmap_atlas(scene, settings, "test.gltf", diagnostics);
}

TexelGBuffer raster(const Scene& scene, const AtlasLayout& atlas) {
  Diagnostics diagnostics;
  return rasterize_texel_gbuffer(scene, atlas, "test.gltf", diagnostics);
}

// What exitance-relight starts from: the scene through scene.bin.
PersistedScene persisted_from(const json& d) {
  const Scene scene = import_document(d);
  const AtlasLayout atlas = layout_of(scene);
  const formats::SceneFile file = make_scene_file(scene, raster(scene, atlas), atlas, nullptr, to_scene_bvh(build_bvh4(scene)));
  const std::vector<uint8_t> bytes = formats::encode_scene(file);
  return restore_scene(formats::read_scene(bytes.data(), bytes.size(), "scene.bin"));
}

const PersistedScene& baked() {
  static const PersistedScene p = persisted_from(scene_document());
  return p;
}

// Bit for bit: scene.bin's bytes cover the scene, G-buffer, atlas and BVH; the sky's constant and
// the cone cosines are in them too.
std::vector<uint8_t> bytes_of(const PersistedScene& p) {
  return formats::encode_scene(make_scene_file(p.scene, p.gbuffer, p.atlas, nullptr, p.bvh));
}

std::string edit_error(PersistedScene& p, const std::vector<SceneEdit>& edits) {
  try {
    apply_scene_edits(p, edits);
  } catch (const SceneEditError& e) {
    return e.what();
  }
  return "accepted";
}

std::string parse_error(const std::string& text) {
  try {
    parse_scene_edits(text, "edits.json");
  } catch (const SceneEditError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(SceneEditsParse, ReadsEveryEditType) {
  const std::vector<SceneEdit> edits = parse_scene_edits(R"({"edits": [
      {"node": "sun", "rotation": [0, 0, 0, 1]}, {"node": 1, "translation": [1, 2, 3], "scale": [2, 2, 2]},
      {"light": "Lamp", "intensity": 5.0, "color": [1, 0.9, 0.8], "innerConeAngle": 0.2, "outerConeAngle": 0.6},
      {"material": "Panel", "emissiveStrength": 2.0, "emissiveFactor": [1, 1, 1]}, {"sky": [0.3, 0.4, 0.5]}]})",
                                                         "edits.json");
  ASSERT_EQ(edits.size(), 5u);
  const auto& sun = std::get<NodeEdit>(edits[0].change);
  EXPECT_EQ(sun.node.name, "sun");
  EXPECT_EQ(sun.rotation, (std::array<double, 4>{0, 0, 0, 1}));
  EXPECT_FALSE(sun.translation || sun.scale);
  const auto& box = std::get<NodeEdit>(edits[1].change);
  EXPECT_EQ(box.node.index, 1u);
  EXPECT_EQ(box.translation, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(edits[1].where, "edits.json: edits[1] (node 1)");
  const auto& lamp = std::get<LightEdit>(edits[2].change);
  EXPECT_EQ(lamp.intensity, 5.0f);
  EXPECT_EQ(lamp.color, (std::array<float, 3>{1, 0.9f, 0.8f}));
  EXPECT_EQ(lamp.inner_cone_angle, 0.2);
  EXPECT_EQ(lamp.outer_cone_angle, 0.6);
  EXPECT_EQ(edits[2].where, "edits.json: edits[2] (light \"Lamp\")");
  const auto& panel = std::get<MaterialEdit>(edits[3].change);
  EXPECT_EQ(panel.emissive_strength, 2.0f);
  EXPECT_EQ(panel.emissive_factor, (std::array<float, 3>{1, 1, 1}));
  EXPECT_EQ(std::get<SkyEdit>(edits[4].change).color, (std::array<float, 3>{0.3f, 0.4f, 0.5f}));
  EXPECT_EQ(edits[4].where, "edits.json: edits[4] (sky)");
}

TEST(SceneEditsParse, ErrorsAreOneLineNamingTheEditAndField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"edits": [{"sky": [0, 0, 0]}, {"light": "Lamp", "intensity": -1}]})",
       R"(edits.json: edits[1] (light "Lamp"): intensity: -1 is negative)"},
      {R"({"edits": [{"node": "Box", "translaton": [1, 2, 3]}]})",
       R"(edits.json: edits[0] (node "Box"): unknown key "translaton" (this edit takes node, translation, rotation, scale))"},
      {R"({"edits": [{"node": "Box", "scale": [1, 0, 1]}]})",
       R"(edits.json: edits[0] (node "Box"): scale: component 1 is 0 (the transform would not be invertible))"},
      {R"({"edits": [{"node": "Box", "rotation": [0, 90, 0, 1]}]})",
       R"(edits.json: edits[0] (node "Box"): rotation: length 90.00555538409837 is not 1 (a unit quaternion [x, y, z, w]))"},
      {R"({"edits": [{"node": "Box", "translation": [1, 2]}]})",
       R"(edits.json: edits[0] (node "Box"): translation: must be an array of 3 numbers)"},
      {R"({"edits": [{"node": 2.5, "translation": [1, 2, 3]}]})",
       R"(edits.json: edits[0]: "node" must be a name (string) or an index (integer >= 0))"},
      {R"({"edits": [{"node": -1, "translation": [1, 2, 3]}]})",
       R"(edits.json: edits[0]: "node" must be a name (string) or an index (integer >= 0))"},
      {R"({"edits": [{"node": "Box"}]})", R"(edits.json: edits[0] (node "Box"): changes nothing (give translation, rotation or scale))"},
      {R"({"edits": [{"light": "Lamp", "color": [1, 2, 0]}]})",
       R"(edits.json: edits[0] (light "Lamp"): color: 2 is outside [0, 1] (glTF colours; scale with intensity))"},
      {R"({"edits": [{"light": "Lamp", "innerConeAngle": 0.6, "outerConeAngle": 0.2}]})",
       R"(edits.json: edits[0] (light "Lamp"): innerConeAngle: 0.6 is not below outerConeAngle 0.2)"},
      {R"({"edits": [{"light": "Lamp", "outerConeAngle": 2}]})",
       R"(edits.json: edits[0] (light "Lamp"): outerConeAngle: 2 is outside [0, pi/2] (radians))"},
      {R"({"edits": [{"material": "Panel", "emissiveStrength": "2"}]})",
       R"(edits.json: edits[0] (material "Panel"): emissiveStrength: must be a number)"},
      {R"({"edits": [{"material": "Panel", "emissiveStrength": 1e39}]})",
       R"(edits.json: edits[0] (material "Panel"): emissiveStrength: inf is not a finite number)"},
      {R"({"edits": [{"sky": [0.1, -0.2, 0]}]})", R"(edits.json: edits[0] (sky): sky: -0.2 is negative)"},
      {R"({"edits": [{"sky": [0, 0, 0], "light": "Lamp"}]})",
       R"(edits.json: edits[0]: has both "light" and "sky" (one thing per edit))"},
      {R"({"edits": [{"colour": [1, 1, 1]}]})",
       R"(edits.json: edits[0]: names nothing to edit (give "node", "light", "material" or "sky"))"},
      {R"({"edits": [3]})", R"(edits.json: edits[0]: must be an object)"},
      {R"({"edits": {}})", R"(edits.json: "edits" must be an array)"},
      {R"({"edit": []})", R"(edits.json: must be an object {"edits": [...]})"},
      {R"({"edits": [], "version": 1})", R"(edits.json: unknown key "version" (the document takes only "edits"))"},
  };
  for (const auto& [text, expected] : cases) EXPECT_EQ(parse_error(text), expected) << text;
  const std::string not_json = parse_error(R"({"edits": [)");
  EXPECT_TRUE(not_json.starts_with("edits.json: not valid JSON: ")) << not_json;
  EXPECT_EQ(not_json.find('\n'), std::string::npos) << not_json;
}

SceneEdit node_edit(const std::string& name, std::optional<std::array<double, 3>> translation,
                    std::optional<std::array<double, 4>> rotation = std::nullopt,
                    std::optional<std::array<double, 3>> scale = std::nullopt) {
  NodeEdit e;
  e.node.name = name;
  e.translation = translation;
  e.rotation = rotation;
  e.scale = scale;
  return {e, ""};
}

SceneEdit light_intensity(EditTarget target, float intensity) {
  LightEdit e;
  e.light = std::move(target);
  e.intensity = intensity;
  return {e, ""};
}

// Each bad edit throws a one-line SceneEditError and leaves the scene as it was, even after good
// edits earlier in the same list (all or nothing).
TEST(SceneEditsApply, BadEditsLeaveTheSceneUnchanged) {
  const std::vector<uint8_t> before = bytes_of(baked());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const SceneEdit good_move = node_edit("Box", std::array<double, 3>{5, 0, 0});
  SceneEdit point_cone;
  {
    LightEdit e;
    e.light.name = "Sun";
    e.outer_cone_angle = 0.5;
    point_cone = {e, ""};
  }
  SceneEdit collapsing_cone;  // inner as baked (0.2) is not below the new outer angle
  {
    LightEdit e;
    e.light.name = "Lamp";
    e.outer_cone_angle = 0.1;
    collapsing_cone = {e, ""};
  }
  const std::vector<std::pair<std::vector<SceneEdit>, std::string>> cases = {
      {{good_move, node_edit("Bx", std::array<double, 3>{0, 0, 0})}, R"(edits[1] (node "Bx"): no node is named "Bx")"},
      {{good_move, node_edit("Twin", std::array<double, 3>{0, 0, 0})},
       R"(edits[1] (node "Twin"): 2 nodes are named "Twin" (nodes 5, 6); give the index of one instead of the name)"},
      {{light_intensity(EditTarget{"", 7}, 1)}, R"(edits[0] (light 7): light 7 does not exist (the scene has 2 lights))"},
      {{good_move, node_edit("Box", std::array<double, 3>{0, nan, 0})}, R"(edits[1] (node "Box"): translation: nan is not a finite number)"},
      {{good_move, light_intensity(EditTarget{"Lamp", {}}, -1)}, R"(edits[1] (light "Lamp"): intensity: -1 is negative)"},
      {{good_move, node_edit("Root", std::nullopt, std::nullopt, std::array<double, 3>{1, 0, 1})},
       R"(edits[1] (node "Root"): scale: component 1 is 0 (the transform would not be invertible))"},
      {{good_move, node_edit("Root", std::nullopt, std::nullopt, std::array<double, 3>{1e-300, 1e-300, 1e-300})},
       R"(edits[1] (node "Root"): the world transform of node 0 is singular)"},
      {{point_cone}, R"(edits[0] (light "Sun"): outerConeAngle: light "Sun" is not a spot light)"},
      {{collapsing_cone}, R"(edits[0] (light "Lamp"): outerConeAngle: inner 0.1999999 is not below outer 0.1 (the other angle as baked))"},
  };
  for (const auto& [edits, expected] : cases) {
    PersistedScene p = baked();
    EXPECT_EQ(edit_error(p, edits), expected);
    EXPECT_EQ(bytes_of(p), before) << expected;
  }
}

TEST(SceneEditsApply, AnIndexNamesWhatANameCannot) {
  PersistedScene p = baked();
  const std::array<double, 3> moved{0, 7, 0};
  NodeEdit e;
  e.node.index = 6;
  e.translation = moved;
  const EditEffects effects = apply_scene_edits(p, {{e, ""}});
  EXPECT_EQ(p.scene.nodes[6].translation, moved);
  EXPECT_EQ(p.scene.nodes[5].translation, baked().scene.nodes[5].translation);
  ASSERT_EQ(effects.moved_instances.size(), 1u);
  EXPECT_EQ(p.scene.instances[effects.moved_instances[0]].node, 6);
}

TEST(SceneEditsApply, ANoOpEditLeavesTheSceneBitIdentical) {
  PersistedScene p = baked();
  const std::array<double, 3> same = baked().scene.nodes[1].translation;
  const EditEffects effects = apply_scene_edits(p, {node_edit("Box", same), node_edit("Group", std::array<double, 3>{0, 2, 0})});
  EXPECT_TRUE(effects.moved_instances.empty());
  EXPECT_TRUE(effects.lights.empty());
  EXPECT_EQ(bytes_of(p), bytes_of(baked()));
}

// The scene as importing `d` gives it, rasterized into the baked atlas (the layout stays as baked).
struct Reimported {
  Scene scene;
  TexelGBuffer gbuffer;
};
Reimported reimport(const json& d) {
  Reimported r{import_document(d), {}};
  r.gbuffer = raster(r.scene, baked().atlas);
  return r;
}

float largest_coordinate(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  float m = 0;
  for (const auto* v : {&a, &b})
    for (Vec3 p : *v) m = std::max({m, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  return m;
}

// Edited positions against the importer's: the stored float positions carry <= 2^-24 |p| of
// rounding each, which the edit's linear part (norm `delta_norm`) carries over, plus one rounding
// on each side: |difference| <= (sqrt(3) delta_norm + 2) 2^-24 max|p| per component.
void expect_geometry_as_imported(const PersistedScene& edited, const Reimported& r, double delta_norm) {
  const Scene& a = edited.scene;
  const Scene& b = r.scene;
  ASSERT_EQ(a.positions.size(), b.positions.size());
  const double position_tolerance =
      (std::sqrt(3.0) * delta_norm + 2) * kHalfUlp * largest_coordinate(a.positions, b.positions);
  // Unit normals: each side rounds a normalization (a few 2^-24); 16 of them is the bound used.
  const double normal_tolerance = 16 * kHalfUlp * std::max(1.0, delta_norm);
  for (size_t i = 0; i < a.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(a.positions[i][c], b.positions[i][c], position_tolerance) << "vertex " << i;
      ASSERT_NEAR(a.normals[i][c], b.normals[i][c], normal_tolerance) << "vertex " << i;
    }
  EXPECT_EQ(a.lightmap_uv.size(), b.lightmap_uv.size());
  for (size_t i = 0; i < a.lightmap_uv.size(); ++i) ASSERT_EQ(a.lightmap_uv[i].x, b.lightmap_uv[i].x) << i;
  for (size_t k = 0; k < a.instances.size(); ++k) EXPECT_EQ(a.instances[k].world, b.instances[k].world) << "instance " << k;
  for (size_t l = 0; l < a.lights.size(); ++l) {
    EXPECT_EQ(a.lights[l].position.x, b.lights[l].position.x) << "light " << l;
    EXPECT_EQ(a.lights[l].position.y, b.lights[l].position.y) << "light " << l;
    EXPECT_EQ(a.lights[l].position.z, b.lights[l].position.z) << "light " << l;
    EXPECT_EQ(a.lights[l].direction.x, b.lights[l].direction.x) << "light " << l;
    EXPECT_EQ(a.lights[l].direction.y, b.lights[l].direction.y) << "light " << l;
    EXPECT_EQ(a.lights[l].direction.z, b.lights[l].direction.z) << "light " << l;
  }
  // Texels: the same texels (the atlas stays), at the importer's surface points within the
  // positions' tolerance (an interpolation adds 3 roundings), with its normals and texel sizes.
  ASSERT_EQ(edited.gbuffer.texels.size(), r.gbuffer.texels.size());
  const double texel_tolerance = position_tolerance + 3 * kHalfUlp * largest_coordinate(a.positions, b.positions);
  for (size_t i = 0; i < r.gbuffer.texels.size(); ++i) {
    const LiveTexel& t = edited.gbuffer.texels[i];
    const LiveTexel& u = r.gbuffer.texels[i];
    ASSERT_EQ(t.triangle, u.triangle);
    ASSERT_EQ(t.x, u.x);
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(t.position[c], u.position[c], texel_tolerance) << "texel " << i;
      ASSERT_NEAR(t.shading_normal[c], u.shading_normal[c], normal_tolerance) << "texel " << i;
      ASSERT_NEAR(t.geometric_normal[c], u.geometric_normal[c], normal_tolerance * 4) << "texel " << i;
    }
    ASSERT_NEAR(t.world_texel_size, u.world_texel_size, 8 * kHalfUlp * u.world_texel_size) << "texel " << i;
  }
}

// Moving "Box" equals importing the glTF with Box's translation changed; moving "Root" moves the
// lights and every instance below it; the edited scene is still one scene.bin accepts.
TEST(SceneEditsApply, TranslationEqualsImportingTheMovedNode) {
  for (const auto& [node, index] : {std::pair<std::string, int>{"Box", 1}, {"Root", 0}}) {
    PersistedScene p = baked();
    const std::array<double, 3> moved{-2.5, 1.25, 0.75};
    const EditEffects effects = apply_scene_edits(p, {node_edit(node, moved)});
    json d = scene_document();
    d["nodes"][index]["translation"] = moved;
    expect_geometry_as_imported(p, reimport(d), 1.0);
    EXPECT_TRUE(effects.geometry_changed());
    EXPECT_EQ(effects.moved_instances.size(), node == "Box" ? 1u : p.scene.instances.size());
    EXPECT_EQ(effects.lights.size(), node == "Box" ? 0u : 2u);
    EXPECT_GT(effects.moved_texels, 0u);
    EXPECT_NO_THROW(bytes_of(p));  // texels re-derived as the codec derives them
  }
}

// Rotating the sun's node turns the light as the importer would (bit for bit: the same matrices).
TEST(SceneEditsApply, RotatingALightsNodeTurnsTheLight) {
  PersistedScene p = baked();
  const std::array<double, 4> q{-0.5, 0.5, 0.0, std::sqrt(0.5)};  // unit
  const EditEffects effects = apply_scene_edits(p, {node_edit("sun", std::nullopt, q)});
  json d = scene_document();
  d["nodes"][2]["rotation"] = q;
  const Scene r = import_document(d);
  // Scene::lights in the order nodes place them: the sun's node (2) before the lamp's (7).
  EXPECT_EQ(effects.lights, std::vector<uint32_t>{0});
  EXPECT_TRUE(effects.moved_instances.empty());
  const PunctualLight& sun = p.scene.lights[0];
  EXPECT_EQ(sun.name, "Sun");
  EXPECT_EQ(sun.direction.x, r.lights[0].direction.x);
  EXPECT_EQ(sun.direction.y, r.lights[0].direction.y);
  EXPECT_EQ(sun.direction.z, r.lights[0].direction.z);
  EXPECT_GT(length(sun.direction - baked().scene.lights[0].direction), 0.1f);
  // Rotating a node by q turns -Z into q (-Z) q*: ((x z + y w) * -2, (y z - x w) * -2, -(1 - 2 (x^2 + y^2))).
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  EXPECT_NEAR(sun.direction.x, -2 * (x * z + y * w), 4 * kHalfUlp);
  EXPECT_NEAR(sun.direction.y, -2 * (y * z - x * w), 4 * kHalfUlp);
  EXPECT_NEAR(sun.direction.z, -(1 - 2 * (x * x + y * y)), 4 * kHalfUlp);
}

// A matrix node is decomposed (a 90 degree turn about Z, translation (0, 2, 0)) before its rotation
// is replaced: as importing the node written as translation/rotation/scale.
TEST(SceneEditsApply, RotatingAMatrixNodeDecomposesIt) {
  PersistedScene p = baked();
  const std::array<double, 4> q{0, 0, 0.38268343236508978, 0.92387953251128674};  // 45 degrees about Z
  apply_scene_edits(p, {node_edit("Group", std::nullopt, q)});
  EXPECT_FALSE(p.scene.nodes[3].has_matrix);
  EXPECT_EQ(p.scene.nodes[3].translation, (std::array<double, 3>{0, 2, 0}));
  EXPECT_EQ(p.scene.nodes[3].scale, (std::array<double, 3>{1, 1, 1}));
  json d = scene_document();
  d["nodes"][3].erase("matrix");
  d["nodes"][3]["translation"] = {0, 2, 0};
  d["nodes"][3]["rotation"] = q;
  expect_geometry_as_imported(p, reimport(d), 1.0);
}

// Scale keeps the texel count (the atlas stays) and scales the world texel size; a mirroring scale
// flips the winding as the importer does, so the front side stays the front side.
TEST(SceneEditsApply, ScaleKeepsTexelsAndMirrorsLikeTheImporter) {
  for (const std::array<double, 3> scale : {std::array<double, 3>{2, 2, 2}, std::array<double, 3>{-1, 1, 1}}) {
    SCOPED_TRACE("scale x " + std::to_string(scale[0]));
    PersistedScene p = baked();
    apply_scene_edits(p, {node_edit("Box", std::nullopt, std::nullopt, scale)});
    json d = scene_document();
    d["nodes"][1]["scale"] = scale;
    expect_geometry_as_imported(p, reimport(d), std::fabs(scale[0]));
    EXPECT_EQ(p.gbuffer.texels.size(), baked().gbuffer.texels.size());
    for (size_t i = 0; i < p.gbuffer.texels.size(); ++i) {
      if (p.scene.instances[p.gbuffer.texels[i].instance].node != 1) continue;
      ASSERT_NEAR(p.gbuffer.texels[i].world_texel_size, std::fabs(scale[0]) * baked().gbuffer.texels[i].world_texel_size,
                  8 * kHalfUlp * p.gbuffer.texels[i].world_texel_size);
    }
    EXPECT_NO_THROW(bytes_of(p));
  }
}

// With a normal map on Box's material (tangents generated from TEXCOORD_1), moving Box turns its
// tangent frames as importing the moved node does: a rotation turns the tangents, a mirroring scale
// also flips their handedness (tangent_frames.h). Tangents are unit vectors from the same kind of
// float products as the normals: the normals' tolerance, times the condition number of the edit's
// linear part (4 for the scale 1, 2, 0.5), which amplifies the stored tangents' rounding.
TEST(SceneEditsApply, MovedNormalMapFramesEqualImportingTheMovedNode) {
  json d = scene_document();
  d["images"] = json::array({{{"uri", "data:image/png;base64,"
                                      "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR42mNoaPgPAAODAgA+WCglAAAAAElFTkSuQmCC"}}});
  d["textures"] = json::array({{{"source", 0}}});
  d["materials"][0]["normalTexture"] = {{"index", 0}, {"texCoord", 1}};
  const PersistedScene mapped = persisted_from(d);
  ASSERT_EQ(mapped.scene.tangents.size(), mapped.scene.positions.size());
  const std::array<double, 4> turn{0.3, -0.4, 0.2, std::sqrt(1 - 0.09 - 0.16 - 0.04)};
  for (const auto& [scale, rotation] : {std::pair{std::array<double, 3>{-1, 1, 1}, std::array<double, 4>{0, 0, 0, 1}},
                                        std::pair{std::array<double, 3>{1, 2, 0.5}, turn}}) {
    SCOPED_TRACE("scale x " + std::to_string(scale[0]));
    PersistedScene p = mapped;
    apply_scene_edits(p, {node_edit("Box", std::nullopt, rotation, scale)});
    json moved = d;
    moved["nodes"][1]["scale"] = scale;
    moved["nodes"][1]["rotation"] = rotation;
    const Scene r = import_document(moved);
    ASSERT_EQ(p.scene.tangents.size(), r.tangents.size());
    const double tolerance = 16 * kHalfUlp * 4;
    size_t flipped = 0;
    for (size_t c = 0; c < r.tangents.size(); ++c) {
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(p.scene.tangents[c][k], r.tangents[c][k], tolerance) << "corner " << c;
      ASSERT_EQ(p.scene.tangent_signs[c], r.tangent_signs[c]) << "corner " << c;
      flipped += p.scene.tangent_signs[c] != mapped.scene.tangent_signs[c];
    }
    // Box's 6 corners flip with the mirror (Twin's, the same mesh, do not); none with the turn.
    EXPECT_EQ(flipped, scale[0] < 0 ? 6u : 0u);
    EXPECT_NO_THROW(bytes_of(p));
  }
}

// A texel the unocclude step pushed off its surface point keeps the push, moved rigidly.
TEST(SceneEditsApply, PushedTexelsMoveRigidly) {
  PersistedScene p = baked();
  size_t pushed = 0;
  while (p.scene.instances[p.gbuffer.texels[pushed].instance].node != 1) ++pushed;
  const Vec3 offset{0.01f, -0.02f, 0.03f};
  p.gbuffer.texels[pushed].position = p.gbuffer.texels[pushed].position + offset;
  const Vec3 old_position = p.gbuffer.texels[pushed].position;
  const Matrix4d old_world = p.scene.instances[p.gbuffer.texels[pushed].instance].world;
  apply_scene_edits(p, {node_edit("Box", std::array<double, 3>{0, 4, 0})});
  const Matrix4d& new_world = p.scene.instances[p.gbuffer.texels[pushed].instance].world;
  const Vec3 expected = transform_point(multiply(new_world, *affine_inverse(old_world)), old_position);
  EXPECT_EQ(p.gbuffer.texels[pushed].position.x, expected.x);
  EXPECT_EQ(p.gbuffer.texels[pushed].position.y, expected.y);
  EXPECT_EQ(p.gbuffer.texels[pushed].position.z, expected.z);
  EXPECT_NO_THROW(bytes_of(p));  // kept in scene.bin's moved-texel table
}

TEST(SceneEditsApply, LightIntensityAndColourKeepTheOtherPart) {
  PersistedScene p = baked();
  ASSERT_EQ(baked().scene.lights[1].name, "Lamp");
  const Vec3 baked_intensity = baked().scene.lights[1].intensity;  // (1, 0.9, 0.8) x 5
  const EditEffects effects = apply_scene_edits(p, {light_intensity(EditTarget{"Lamp", {}}, 2)});
  EXPECT_EQ(effects.lights, std::vector<uint32_t>{1});
  // colour = product / 5 and x 2: three float roundings of a value <= 2.
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(p.scene.lights[1].intensity[c], baked_intensity[c] * 2 / 5, 3 * 2 * kHalfUlp * 2);
  LightEdit colour;
  colour.light.name = "Lamp";
  colour.color = {0.5f, 1.0f, 0.25f};
  colour.inner_cone_angle = 0.1;
  colour.outer_cone_angle = 0.9;
  apply_scene_edits(p, {{colour, ""}});
  EXPECT_NEAR(p.scene.lights[1].intensity.x, 1.0f, 3 * 2 * kHalfUlp * 2);  // intensity 2 kept
  EXPECT_NEAR(p.scene.lights[1].intensity.y, 2.0f, 3 * 2 * kHalfUlp * 2);
  EXPECT_NEAR(p.scene.lights[1].intensity.z, 0.5f, 3 * 2 * kHalfUlp * 2);
  EXPECT_EQ(p.scene.lights[1].cos_inner, float(std::cos(0.1)));
  EXPECT_EQ(p.scene.lights[1].cos_outer, float(std::cos(0.9)));
}

TEST(SceneEditsApply, EmissionStrengthAndFactorKeepTheOtherPart) {
  PersistedScene p = baked();
  MaterialEdit strength;
  strength.material.name = "Panel";
  strength.emissive_strength = 4;
  const EditEffects effects = apply_scene_edits(p, {{strength, ""}});
  EXPECT_EQ(effects.materials, std::vector<uint32_t>{1});
  EXPECT_EQ(p.scene.materials[1].emission.x, 4.0f);  // factor (1, 0.5, 0.25) as baked, strength 1
  EXPECT_EQ(p.scene.materials[1].emission.y, 2.0f);
  EXPECT_EQ(p.scene.materials[1].emission.z, 1.0f);
  MaterialEdit factor;
  factor.material.name = "Panel";
  factor.emissive_factor = {0.5f, 0.5f, 1.0f};
  apply_scene_edits(p, {{factor, ""}});
  EXPECT_EQ(p.scene.materials[1].emission.x, 2.0f);  // strength 4 kept
  EXPECT_EQ(p.scene.materials[1].emission.z, 4.0f);
}

TEST(SceneEditsApply, SkySetsTheConstantRadiance) {
  PersistedScene p = baked();
  const EditEffects effects = apply_scene_edits(p, {{SkyEdit{{0.3f, 0.4f, 0.5f}}, ""}});
  EXPECT_TRUE(effects.sky);
  EXPECT_FALSE(effects.geometry_changed());
  EXPECT_EQ(p.scene.sky.constant.y, 0.4f);
}

// Every triangle a leaf holds lies inside every box on the path to it.
void expect_boxes_contain_their_triangles(const Bvh4& bvh, const std::vector<Vec3>& positions) {
  size_t checked = 0;
  const auto visit = [&](auto&& self, uint32_t node, std::vector<std::pair<uint32_t, int>>& path) -> void {
    for (int i = 0; i < 4; ++i) {
      const uint32_t child = bvh.nodes[node].child[i];
      if (child == kBvhEmptyChild) continue;
      path.push_back({node, i});
      if (child & kBvhLeafBit) {
        const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
        for (uint32_t s = first; s < first + count; ++s)
          for (int k = 0; k < 3; ++k) {
            const Vec3 p = positions[size_t(bvh.leaf_triangles[s]) * 3 + size_t(k)];
            for (const auto& [n, c] : path) {
              const Bvh4Node& b = bvh.nodes[n];
              ASSERT_TRUE(b.lo_x[c] <= p.x && p.x <= b.hi_x[c] && b.lo_y[c] <= p.y && p.y <= b.hi_y[c] &&
                          b.lo_z[c] <= p.z && p.z <= b.hi_z[c])
                  << "triangle " << bvh.leaf_triangles[s] << " outside node " << n << " child " << c;
            }
            ++checked;
          }
      } else {
        self(self, child, path);
      }
      path.pop_back();
    }
  };
  std::vector<std::pair<uint32_t, int>> path;
  visit(visit, 0, path);
  EXPECT_EQ(checked, positions.size());
}

TEST(Bvh4Refit, MovedTrianglesStayInsideEveryBoxAbove) {
  PersistedScene p = baked();
  const Bvh4 built = to_bvh4(p.bvh);
  // The builder's boxes are the triangles' exact bounds: a refit of unmoved geometry keeps them.
  Bvh4 same = built;
  refit_bvh4(same, p.scene.positions);
  ASSERT_EQ(same.nodes.size(), built.nodes.size());
  EXPECT_EQ(std::memcmp(same.nodes.data(), built.nodes.data(), built.nodes.size() * sizeof(Bvh4Node)), 0);

  apply_scene_edits(p, {node_edit("Box", std::array<double, 3>{-8, 3, 2}, std::array<double, 4>{0.6, 0, 0, 0.8})});
  const Bvh4 refit = to_bvh4(p.bvh);
  EXPECT_EQ(refit.leaf_triangles, built.leaf_triangles);
  EXPECT_NE(std::memcmp(refit.nodes.data(), built.nodes.data(), built.nodes.size() * sizeof(Bvh4Node)), 0);
  expect_boxes_contain_their_triangles(refit, p.scene.positions);

  Bvh4 broken = built;
  broken.leaf_triangles[0] = uint32_t(p.scene.triangle_count());
  EXPECT_THROW(refit_bvh4(broken, p.scene.positions), std::invalid_argument);
}

// A spatial-split builder's leaf holds a fragment of a triangle: its box is tighter than the
// triangle's bounds. Refit against the positions the boxes were fitted to, a leaf whose triangles
// did not move keeps that box; a leaf with a moved triangle gets the box of each triangle's part in
// it, carried to where the triangle went; inner boxes are their children's union. Without the
// fitted positions every leaf gets its triangles' whole bounds.
TEST(Bvh4Refit, LeavesOfUnmovedTrianglesKeepTheirFragmentBoxes) {
  // Triangle 0 spans x in [0, 2] and is split at x = 1 into two leaves; triangle 1 is a small one far away.
  const std::vector<Vec3> before = {{0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {5, 5, 5}, {6, 5, 5}, {5, 6, 5}};
  Bvh4 bvh;
  bvh.leaf_triangles = {0, 0, 1};
  Bvh4Node root{};
  auto set_box = [](Bvh4Node& n, int i, Vec3 lo, Vec3 hi) {
    n.lo_x[i] = lo.x, n.lo_y[i] = lo.y, n.lo_z[i] = lo.z, n.hi_x[i] = hi.x, n.hi_y[i] = hi.y, n.hi_z[i] = hi.z;
  };
  for (int i = 0; i < 4; ++i) set_box(root, i, {INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}), root.child[i] = kBvhEmptyChild;
  root.child[0] = kBvhLeafBit | (0u << 2) | 0u;  // slot 0: triangle 0's part with x <= 1
  root.child[1] = kBvhLeafBit | (1u << 2) | 0u;  // slot 1: its part with x >= 1
  root.child[2] = kBvhLeafBit | (2u << 2) | 0u;  // slot 2: triangle 1
  set_box(root, 0, {0, 0, 0}, {1, 1, 0});
  set_box(root, 1, {1, 0, 0}, {2, 0.5f, 0});
  set_box(root, 2, {5, 5, 5}, {6, 6, 5});
  bvh.nodes = {root};

  Bvh4 same = bvh;
  refit_bvh4(same, before, &before);
  EXPECT_EQ(std::memcmp(same.nodes.data(), bvh.nodes.data(), sizeof(Bvh4Node)), 0) << "unmoved fragments keep their boxes";

  std::vector<Vec3> after = before;  // triangle 1 moves up by 1
  for (int k = 3; k < 6; ++k) after[size_t(k)].z += 1;
  Bvh4 partly = bvh;
  refit_bvh4(partly, after, &before);
  const Bvh4Node& n = partly.nodes[0];
  EXPECT_EQ(n.hi_x[0], 1.0f) << "triangle 0's fragments kept";
  EXPECT_EQ(n.lo_x[1], 1.0f);
  EXPECT_EQ(n.hi_y[1], 0.5f);
  EXPECT_EQ(n.lo_z[2], 6.0f) << "the moved triangle's leaf refit";
  EXPECT_EQ(n.hi_z[2], 6.0f);
  EXPECT_EQ(n.lo_x[2], 5.0f);
  EXPECT_EQ(n.hi_y[2], 6.0f);

  // Triangle 0 turned and moved: its two fragments' boxes go with it, and between them still hold
  // every point of the moved triangle, each well inside the triangle's whole bounds.
  std::vector<Vec3> turned = before;
  const float c = std::cos(0.7f), s = std::sin(0.7f);
  for (int k = 0; k < 3; ++k) {
    const Vec3 v = before[size_t(k)];
    turned[size_t(k)] = Vec3{c * v.x - s * v.z + 0.3f, v.y - 2.0f, s * v.x + c * v.z + 7.1f};
  }
  Bvh4 carried = bvh;
  refit_bvh4(carried, turned, &before);
  const Bvh4Node& m = carried.nodes[0];
  auto inside = [&](int i, Vec3 p) {
    return m.lo_x[i] <= p.x && p.x <= m.hi_x[i] && m.lo_y[i] <= p.y && p.y <= m.hi_y[i] && m.lo_z[i] <= p.z && p.z <= m.hi_z[i];
  };
  for (int a = 0; a <= 64; ++a)
    for (int b = 0; a + b <= 64; ++b) {
      const float u = float(a) / 64, v = float(b) / 64;
      const Vec3 p = turned[0] + (turned[1] - turned[0]) * u + (turned[2] - turned[0]) * v;
      ASSERT_TRUE(inside(0, p) || inside(1, p)) << "point (" << u << ", " << v << ") of the moved triangle in no fragment";
    }
  WorldBox whole;
  for (int k = 0; k < 3; ++k) whole.grow(turned[size_t(k)]);
  for (int i = 0; i < 2; ++i)
    EXPECT_LT((m.hi_x[i] - m.lo_x[i]) * (m.hi_y[i] - m.lo_y[i]), 0.8f * (whole.hi.x - whole.lo.x) * (whole.hi.y - whole.lo.y))
        << "fragment " << i << " widened to the whole triangle";

  Bvh4 all = bvh;
  refit_bvh4(all, after);
  EXPECT_EQ(all.nodes[0].hi_x[0], 2.0f) << "without the fitted positions a fragment widens to its triangle";
  EXPECT_EQ(all.nodes[0].lo_x[1], 0.0f);
  const std::vector<Vec3> one_triangle(3);
  EXPECT_THROW(refit_bvh4(all, after, &one_triangle), std::invalid_argument);
}

// set_geometry derives what build_lighting_scene derives from the edited scene, over the refit BVH.
TEST(LightingSceneGeometry, SetGeometryEqualsABuildOfTheEditedScene) {
  PersistedScene p = baked();
  LightingScene lighting = build_lighting_scene(std::make_shared<const Scene>(p.scene), to_bvh4(p.bvh));
  apply_scene_edits(p, {node_edit("Group", std::array<double, 3>{0, 5, 1}), node_edit("Root", std::nullopt, std::nullopt,
                                                                                      std::array<double, 3>{3, 3, 3})});
  const auto edited = std::make_shared<const Scene>(p.scene);
  set_geometry(lighting, edited);
  const LightingScene fresh = build_lighting_scene(edited, to_bvh4(p.bvh));
  ASSERT_EQ(lighting.triangles.size(), fresh.triangles.size());
  EXPECT_EQ(std::memcmp(lighting.triangles.data(), fresh.triangles.data(), fresh.triangles.size() * sizeof(GpuTriangle)), 0);
  EXPECT_EQ(std::memcmp(lighting.bvh.nodes.data(), fresh.bvh.nodes.data(), fresh.bvh.nodes.size() * sizeof(Bvh4Node)), 0);
  EXPECT_EQ(lighting.emitter_cdf, fresh.emitter_cdf);
  EXPECT_EQ(lighting.emitter_inverse_power, fresh.emitter_inverse_power);
  EXPECT_EQ(lighting.punctual_cdf, fresh.punctual_cdf);
  EXPECT_EQ(std::memcmp(lighting.punctual_lights.data(), fresh.punctual_lights.data(),
                        fresh.punctual_lights.size() * sizeof(GpuPunctualLight)), 0);
  EXPECT_EQ(lighting.extent, fresh.extent);
  EXPECT_GT(lighting.extent, 2.5f * build_lighting_scene(std::make_shared<const Scene>(baked().scene), {}).extent);

  Scene fewer = p.scene;
  fewer.triangle_material.pop_back();
  const LightingScene kept = lighting;
  EXPECT_THROW(set_geometry(lighting, std::make_shared<const Scene>(fewer)), std::invalid_argument);
  EXPECT_EQ(lighting.source, kept.source);
}

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// update_lighting_scene takes the cheapest in-place path that covers the effects, and ends where a
// build of the edited scene over the (refit) BVH starts.
TEST(SceneEditsLighting, UpdateEqualsABuildOfTheEditedScene) {
  MaterialEdit strength;
  strength.material.name = "Panel";
  strength.emissive_strength = 3;
  const std::vector<std::vector<SceneEdit>> cases = {
      {light_intensity(EditTarget{"Lamp", {}}, 9), {strength, ""}, {SkyEdit{{0.1f, 0.2f, 0.3f}}, ""}},
      {node_edit("Root", std::array<double, 3>{1, 2, 3}, std::array<double, 4>{0, 0.6, 0, 0.8}),
       light_intensity(EditTarget{"Sun", {}}, 0.5f)},
  };
  for (size_t c = 0; c < cases.size(); ++c) {
    const std::vector<SceneEdit>& edits = cases[c];
    PersistedScene p = baked();
    LightingScene lighting = build_lighting_scene(std::make_shared<const Scene>(p.scene), to_bvh4(p.bvh));
    const EditEffects effects = apply_scene_edits(p, edits);
    EXPECT_EQ(effects.geometry_changed(), c == 1);
    const auto edited = std::make_shared<const Scene>(p.scene);
    update_lighting_scene(lighting, edited, effects);
    const LightingScene fresh = build_lighting_scene(edited, to_bvh4(p.bvh));
    EXPECT_TRUE(same_bytes(lighting.triangles, fresh.triangles)) << "case " << c;
    EXPECT_TRUE(same_bytes(lighting.materials, fresh.materials)) << "case " << c;
    EXPECT_TRUE(same_bytes(lighting.punctual_lights, fresh.punctual_lights)) << "case " << c;
    EXPECT_TRUE(same_bytes(lighting.bvh.nodes, fresh.bvh.nodes)) << "case " << c;
    EXPECT_EQ(lighting.emitter_triangles, fresh.emitter_triangles) << "case " << c;
    EXPECT_EQ(lighting.emitter_cdf, fresh.emitter_cdf) << "case " << c;
    EXPECT_EQ(lighting.emitter_inverse_power, fresh.emitter_inverse_power) << "case " << c;
    EXPECT_EQ(lighting.punctual_cdf, fresh.punctual_cdf) << "case " << c;
    EXPECT_EQ(lighting.sky.z, fresh.sky.z) << "case " << c;
    EXPECT_EQ(lighting.extent, fresh.extent) << "case " << c;
    EXPECT_EQ(lighting.source, edited) << "case " << c;
  }
}

// The runtime's path: edits applied in place (lights, the sky, materials, nodes that move lights,
// instances, an emissive panel under a matrix node, a mirror) leave the scene, its texels and,
// once the caller refits the BVH over the moved triangles, scene.bin's bytes exactly as
// apply_scene_edits does; the lighting scene refreshed from its own (edited) source equals a
// build of the edited scene; the moved texels listed are those that changed; a bad edit after
// good ones leaves the scene bit for bit as it was.
TEST(SceneEditsApply, InPlaceEqualsTheCopyingPath) {
  LightEdit cone;
  cone.light.name = "Lamp";
  cone.outer_cone_angle = 0.7;
  cone.color = std::array<float, 3>{0.2f, 0.4f, 1.0f};
  MaterialEdit strength;
  strength.material.name = "Panel";
  strength.emissive_strength = 3;
  const std::vector<std::vector<SceneEdit>> cases = {
      {light_intensity(EditTarget{"Lamp", {}}, 9), {cone, ""}},
      {{SkyEdit{{0.1f, 0.2f, 0.3f}}, ""}, light_intensity(EditTarget{"Sun", {}}, 0.5f)},
      {node_edit("LampNode", std::array<double, 3>{1, 4, -2}), node_edit("sun", std::nullopt, std::array<double, 4>{0, 0.6, 0, 0.8})},
      {{strength, ""}},
      {node_edit("Box", std::array<double, 3>{-8, 3, 2}, std::array<double, 4>{0.6, 0, 0, 0.8})},
      {node_edit("Group", std::array<double, 3>{0, 5, 1}), {strength, ""}, light_intensity(EditTarget{"Lamp", {}}, 2)},
      {node_edit("Root", std::nullopt, std::nullopt, std::array<double, 3>{-1, 2, 2})},
  };
  for (size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE("case " + std::to_string(c));
    PersistedScene copied = baked(), in_place = baked();
    const EditEffects expected = apply_scene_edits(copied, cases[c]);
    LightingScene lighting = build_lighting_scene(
        std::shared_ptr<const Scene>(std::shared_ptr<const Scene>{}, &in_place.scene), to_bvh4(in_place.bvh));
    const Bvh4Links links = link_bvh4(lighting.bvh, in_place.scene.triangle_count());
    const InstanceTexels by_instance(in_place.gbuffer, in_place.scene.instances.size());
    const InPlaceEdits edited = apply_scene_edits_in_place(in_place, cases[c], c % 2 ? &by_instance : nullptr);
    const EditEffects& effects = edited.effects;
    EXPECT_EQ(effects.lights, expected.lights);
    EXPECT_EQ(effects.materials, expected.materials);
    EXPECT_EQ(effects.sky, expected.sky);
    EXPECT_EQ(effects.moved_instances, expected.moved_instances);
    EXPECT_EQ(effects.moved_texels, expected.moved_texels);
    std::vector<uint32_t> changed_texels;
    for (size_t i = 0; i < copied.gbuffer.texels.size(); ++i)
      if (std::memcmp(&copied.gbuffer.texels[i], &baked().gbuffer.texels[i], sizeof(LiveTexel)) != 0) changed_texels.push_back(uint32_t(i));
    EXPECT_EQ(edited.moved_texels, changed_texels);
    EXPECT_EQ(edited.moved_boxes_before.size(), effects.moved_instances.size());
    if (effects.geometry_changed()) {
      EXPECT_FALSE(edited.moved_triangles.empty());
      const MovedTrianglesRefresh moved = refresh_moved_triangles_from_source(
          lighting, links, edited.moved_triangles, edited.moved_triangles_before, scene_world_box(in_place.scene));
      for (uint32_t n : moved.bvh_nodes) std::memcpy(&in_place.bvh.nodes[n], &lighting.bvh.nodes[n], sizeof(Bvh4Node));
    }
    EXPECT_EQ(bytes_of(in_place), bytes_of(copied));
    refresh_materials_from_source(lighting, effects.materials);
    refresh_lights_from_source(lighting, effects.lights, effects.sky);
    const LightingScene fresh = build_lighting_scene(std::make_shared<const Scene>(copied.scene), to_bvh4(copied.bvh));
    EXPECT_TRUE(same_bytes(lighting.triangles, fresh.triangles));
    EXPECT_TRUE(same_bytes(lighting.materials, fresh.materials));
    EXPECT_TRUE(same_bytes(lighting.punctual_lights, fresh.punctual_lights));
    EXPECT_TRUE(same_bytes(lighting.bvh.nodes, fresh.bvh.nodes));
    EXPECT_EQ(lighting.emitter_triangles, fresh.emitter_triangles);
    EXPECT_EQ(lighting.emitter_cdf, fresh.emitter_cdf);
    EXPECT_EQ(lighting.punctual_cdf, fresh.punctual_cdf);
    EXPECT_EQ(lighting.sky.x, fresh.sky.x);
    EXPECT_EQ(lighting.extent, fresh.extent);
    EXPECT_EQ(lighting.bounds_lo.y, fresh.bounds_lo.y);
    EXPECT_EQ(lighting.bounds_hi.z, fresh.bounds_hi.z);
    EXPECT_EQ(lighting.textured, fresh.textured);
  }
  for (const std::vector<SceneEdit>& bad :
       {std::vector<SceneEdit>{light_intensity(EditTarget{"Lamp", {}}, 2), light_intensity(EditTarget{"Lamp", {}}, -1)},
        std::vector<SceneEdit>{node_edit("Box", std::array<double, 3>{5, 0, 0}), {strength, ""},
                               node_edit("Group", std::nullopt, std::nullopt, std::array<double, 3>{1, 0, 1})}}) {
    PersistedScene p = baked();
    const InstanceTexels by_instance(p.gbuffer, p.scene.instances.size());
    EXPECT_THROW(apply_scene_edits_in_place(p, bad, &by_instance), SceneEditError);
    EXPECT_EQ(bytes_of(p), bytes_of(baked()));
  }
}

// The texel grid finds the same near texels as a pass over every texel: lights inside, at the edge
// of and outside the texels' bounds, in a flat and scattered G-buffer (cells of one size).
TEST(TexelsNearChange, TheGridFindsWhatAFullPassFinds) {
  PersistedScene p;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    LiveTexel t;
    t.position = {40.0f * u(random), 0.5f * u(random), 25.0f * u(random)};
    p.gbuffer.texels.push_back(t);
  }
  PunctualLight light;
  light.type = PunctualLight::Type::Point;
  p.scene.lights = {light};
  Scene before = p.scene;
  LightingScene lighting;
  lighting.extent = 40.0f;
  EditEffects effects;
  effects.lights = {0};
  const TexelGrid grid(p.gbuffer);
  size_t found = 0;
  for (const Vec3 at : {Vec3{20, 0.2f, 12}, Vec3{0, 0, 0}, Vec3{40, 0.5f, 25}, Vec3{-30, 5, 60}, Vec3{3, -2, 24}}) {
    p.scene.lights[0].position = at;
    before.lights[0].position = at + Vec3{1.5f, 0, -1};
    const std::vector<uint32_t> full = texels_near_change(p, before, lighting, effects);
    EXPECT_EQ(texels_near_change(p, before, lighting, effects, &grid), full) << at.x << " " << at.y << " " << at.z;
    found += full.size();
  }
  EXPECT_GT(found, 1000u);  // the cases are not all empty
  // Texels moved since the grid's build (displaced: their cells no longer hold them), then a box
  // near most texels (the marks path for long lists) and a light (the sorted path for short ones).
  TexelGrid moved_grid(p.gbuffer);
  for (uint32_t i = 0; i < 20000; i += 37) {
    p.gbuffer.texels[i].position = {40.0f * u(random), 0.5f * u(random), 25.0f * u(random)};
    moved_grid.displace(i, p.gbuffer.texels[i]);
  }
  p.scene.lights[0].position = before.lights[0].position = {11, 0.3f, 6};
  const std::vector<uint32_t> full_light = texels_near_change(p, before, lighting, effects);
  EXPECT_EQ(texels_near_change(p, before, lighting, effects, &moved_grid), full_light);
  EditEffects moved_effects;
  moved_effects.moved_instances = {0};
  ChangeBefore was;
  was.moved_boxes_before = {WorldBox{{18, 0, 10}, {22, 0.5f, 14}}};
  was.moved_boxes_after = {WorldBox{{8, 0, 3}, {12, 0.5f, 7}}};
  const std::vector<uint32_t> full_block = texels_near_change(p, was, lighting, moved_effects);
  EXPECT_EQ(texels_near_change(p, was, lighting, moved_effects, &moved_grid), full_block);
  EXPECT_GT(full_block.size(), 20000u / 32);  // long enough for the marks path

  // A low sun (14 degrees up, travelling +x): a box 3-4 m above the texels shades the texels about
  // 13 m further along x, beyond the near radius, and those count too.
  PunctualLight sun;
  sun.type = PunctualLight::Type::Directional;
  sun.direction = normalize(Vec3{0.97f, -0.243f, 0});
  p.scene.lights.push_back(sun);
  lighting.bounds_lo = {0, 0, 0}, lighting.bounds_hi = {40, 0.5f, 25};
  was.moved_boxes_before = {WorldBox{{18, 3, 10}, {22, 4, 14}}};
  was.moved_boxes_after = {WorldBox{{2, 3, 2}, {4, 4, 4}}};
  const size_t shaded = p.gbuffer.texels.size();
  LiveTexel in_shadow, beside;
  in_shadow.position = {35.5f, 0.25f, 12}, beside.position = {35.5f, 0.25f, 20};
  p.gbuffer.texels.push_back(in_shadow), p.gbuffer.texels.push_back(beside);
  const TexelGrid sun_grid(p.gbuffer);
  const std::vector<uint32_t> full_sun = texels_near_change(p, was, lighting, moved_effects);
  EXPECT_TRUE(std::binary_search(full_sun.begin(), full_sun.end(), uint32_t(shaded)));
  EXPECT_FALSE(std::binary_search(full_sun.begin(), full_sun.end(), uint32_t(shaded + 1)));
  std::vector<uint8_t> marks(p.gbuffer.texels.size(), 0);
  EXPECT_EQ(texels_near_change(p, was, lighting, moved_effects, &sun_grid, &marks), full_sun);
  EXPECT_EQ(std::count(marks.begin(), marks.end(), uint8_t(0)), ptrdiff_t(marks.size()));  // left zero
  EXPECT_EQ(texels_near_change(p, was, lighting, moved_effects, &sun_grid, &marks), full_sun);
}

}  // namespace
}  // namespace exitance
