// texels_carried_rigidly (refresh/unocclude_near_moved.h): the texels of a moved instance whose
// unocclude push a move carried with them are exactly those a fresh unocclude step would place
// where the carried push put them. The instance is a "T" (a floor crossing under a wall, so the
// floor texels behind the wall are pushed by its own geometry) above a ground quad; the bake's
// unocclude stage (Embree) places the texels first, as bake does, then the edits move it. Where a
// texel lies within reach of another instance's box, its triangles decide (a box that spans more
// than its triangles keeps no texel from being carried).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/bake/raster/unocclude.h"
#include "exitance/runtime/core/bvh4_closest_hit.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/refresh/scene_edits.h"
#include "exitance/runtime/refresh/unocclude_near_moved.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/texel_surface.h"
#include "exitance/runtime/unocclude_texel.h"
#include "exitance/runtime/world_box.h"

#include "support/base64.h"

namespace exitance {
namespace {

using json = nlohmann::json;

using test::base64;

struct Quad {
  Vec3 corner, u, v, normal;  // corner + s u + t v, s and t in [0, 1]
  float uv_lo_x, uv_hi_x;      // its lightmap UVs: [uv_lo_x, uv_hi_x] x [0.05, 0.95]
};

// Mesh 0, the "T": a floor (y = 0, x in [-0.5, 1]) crossing under a wall (x = -0.03, facing +x),
// placed so that a column of the floor's texels lies behind the wall within its reach. Mesh 1: a 10 m ground quad at y = 0.
json tee_document() {
  const std::vector<std::vector<Quad>> meshes = {
      {{{-0.5f, 0, 1}, {1.5f, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.05f, 0.45f},
       {{-0.03f, 0, 1}, {0, 0, -1}, {0, 1, 0}, {1, 0, 0}, 0.55f, 0.95f}},
      {{{-5, 0, 5}, {10, 0, 0}, {0, 0, -10}, {0, 1, 0}, 0.05f, 0.95f}}};
  std::vector<float> values;
  json views = json::array(), accessors = json::array(), gltf_meshes = json::array();
  for (const std::vector<Quad>& quads : meshes) {
    std::vector<Vec3> positions, normals;
    std::vector<float> uvs;
    for (const Quad& q : quads) {
      const float s[6] = {0, 1, 1, 0, 1, 0}, t[6] = {0, 0, 1, 0, 1, 1};
      for (int k = 0; k < 6; ++k) {
        positions.push_back(q.corner + q.u * s[k] + q.v * t[k]);
        normals.push_back(q.normal);
        uvs.push_back(q.uv_lo_x + (q.uv_hi_x - q.uv_lo_x) * s[k]);
        uvs.push_back(0.05f + 0.9f * t[k]);
      }
    }
    const size_t first = gltf_meshes.size() * 3, count = positions.size();
    Vec3 lo = positions[0], hi = positions[0];
    for (const Vec3& p : positions) lo = min(lo, p), hi = max(hi, p);
    for (const std::vector<float>& block : {std::vector<float>(&positions[0].x, &positions[0].x + 3 * count),
                                            std::vector<float>(&normals[0].x, &normals[0].x + 3 * count), uvs}) {
      views.push_back({{"buffer", 0}, {"byteOffset", values.size() * 4}, {"byteLength", block.size() * 4}});
      values.insert(values.end(), block.begin(), block.end());
    }
    accessors.push_back({{"bufferView", first}, {"componentType", 5126}, {"count", count}, {"type", "VEC3"},
                         {"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}});
    accessors.push_back({{"bufferView", first + 1}, {"componentType", 5126}, {"count", count}, {"type", "VEC3"}});
    accessors.push_back({{"bufferView", first + 2}, {"componentType", 5126}, {"count", count}, {"type", "VEC2"}});
    gltf_meshes.push_back({{"primitives", {{{"attributes", {{"POSITION", first}, {"NORMAL", first + 1}, {"TEXCOORD_1", first + 2}}},
                                            {"material", 0}}}}});
  }
  std::vector<unsigned char> bytes(values.size() * 4);
  std::memcpy(bytes.data(), values.data(), bytes.size());
  json d = json::parse(R"({
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"name": "Tee", "mesh": 0, "translation": [0, 2, 0]}, {"name": "Ground", "mesh": 1}],
    "materials": [{"name": "Grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}}]
  })");
  d["meshes"] = gltf_meshes;
  d["accessors"] = accessors;
  d["bufferViews"] = views;
  d["buffers"] = {{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}};
  return d;
}

// The offline stage up to unocclude (Embree, as bake runs it), through scene.bin.
PersistedScene baked_tee() {
  const auto path = std::filesystem::temp_directory_path() / ("carried_texels_test_" + std::to_string(::getpid()) + ".gltf");
  std::ofstream(path) << tee_document().dump();
  Diagnostics diagnostics;
  const Scene scene = import_gltf(path.string(), ImportOptions{}, diagnostics);
  std::filesystem::remove(path);
  AtlasSettings settings;
  settings.texel_density = 24;
  const AtlasLayout atlas = layout_lightmap_atlas(scene, settings, "tee.gltf", diagnostics);
  TexelGBuffer gbuffer = rasterize_texel_gbuffer(scene, atlas, "tee.gltf", diagnostics);
  const UnoccludeReport report = unocclude_texels(EmbreeScene(scene), gbuffer);
  EXPECT_GT(report.moved, 0u) << "no floor texel within the wall's reach: the T no longer tests a carried push";
  const formats::SceneFile file = make_scene_file(scene, gbuffer, atlas, nullptr, to_scene_bvh(build_bvh4(scene)));
  const std::vector<uint8_t> bytes = formats::encode_scene(file);
  return restore_scene(formats::read_scene(bytes.data(), bytes.size(), "scene.bin"));
}

SceneEdit move_tee(std::array<double, 3> translation, std::optional<std::array<double, 4>> rotation = std::nullopt,
                   std::optional<std::array<double, 3>> scale = std::nullopt) {
  NodeEdit e;
  e.node.name = "Tee";
  e.translation = translation;
  e.rotation = rotation;
  e.scale = scale;
  return {e, ""};
}

struct Carried {
  std::vector<uint32_t> moved, carried;
  size_t carried_pushed = 0;  // carried texels off their surface point (a push carried along)
};

// Applies `edit`, finds the carried texels, and checks each against a fresh unocclude step on the
// edited scene (its surface point through unocclude_texel, as unocclude_near_boxes places texels):
// the same position up to rounding after a translation and uniform scale (`same_rays`); after a
// rotation the step's 8 sideways rays keep their world directions, not the object's, so the fresh
// push may end elsewhere past the same back face: then the carried texel must be one the step leaves
// where it is (no back face within reach) and lie within the reach of the fresh position.
// With `triangles`, where a texel lies within reach of another instance's box its triangles are
// tested (texels_carried_rigidly's `edited_lighting`); `ground_box`: the box the ground instance is
// given instead of its own (a box that spans more than its triangles, as a city's street floor's).
Carried check_carried(const SceneEdit& edit, bool same_rays = true, bool triangles = true,
                      std::optional<WorldBox> ground_box = std::nullopt) {
  PersistedScene p = baked_tee();
  std::vector<WorldBox> boxes;
  for (const Instance& instance : p.scene.instances) boxes.push_back(instance_world_box(p.scene, instance));
  const InPlaceEdits edited = apply_scene_edits_in_place(p, {edit}, nullptr);
  for (size_t j = 0; j < edited.effects.moved_instances.size(); ++j) boxes[edited.effects.moved_instances[j]] = edited.moved_boxes_after[j];
  if (ground_box) boxes[1] = *ground_box;
  const LightingScene lighting = build_lighting_scene(std::make_shared<const Scene>(p.scene), build_bvh4(p.scene));
  Carried out;
  out.moved = edited.moved_texels;
  out.carried = texels_carried_rigidly(p, edited.moved_texels, edited.effects.moved_instances, edited.moved_deltas,
                                       edited.moved_boxes_before, boxes, WorldBox{}, triangles ? &lighting : nullptr);
  const ClosestHitQuery query = [&](const Vec3& origin, const Vec3& direction, float t_max) {
    const BvhHit hit = closest_hit(lighting, origin, direction, t_max);
    return OccluderHit{hit.found, hit.distance, hit.geometric_normal};
  };
  for (uint32_t i : out.carried) {
    const LiveTexel& texel = p.gbuffer.texels[i];
    const AtlasPage& page = p.gbuffer.pages[texel.page];
    float b1, b2;
    texel_barycentrics(p.scene, p.atlas.rects[texel.instance], page.width, page.height, texel.triangle, texel.x, texel.y, b1, b2);
    LiveTexel fresh = texel;
    fresh.position = texel_surface(p.scene, texel.triangle, b1, b2).position;
    const bool off_surface = length(texel.position - fresh.position) > 1e-4f * texel.world_texel_size;
    out.carried_pushed += off_surface;
    unocclude_texel(fresh, lighting.extent, query);
    LiveTexel again = texel;
    EXPECT_FALSE(unocclude_texel(again, lighting.extent, query)) << "texel " << i << " carried behind a surface";
    // Rounding only: the carried push went through a double transform, the fresh one through rays.
    EXPECT_LE(length(texel.position - fresh.position), (same_rays ? 1e-3f : 1.0f) * unocclude_reach(texel))
        << "texel " << i << " carried to " << texel.position.x << ", " << texel.position.y << ", " << texel.position.z
        << "; a fresh unocclude places it at " << fresh.position.x << ", " << fresh.position.y << ", " << fresh.position.z;
  }
  return out;
}

TEST(TexelsCarriedRigidly, FarFromOtherGeometryEveryTexelIsCarriedWithItsPush) {
  const Carried c = check_carried(move_tee({2, 3, -1}));
  EXPECT_GT(c.moved.size(), 100u);
  EXPECT_EQ(c.carried, c.moved);   // nothing else within reach, before (2 m up) or after (3 m up)
  EXPECT_GT(c.carried_pushed, 0u);  // the floor texels behind the wall kept their push
}

TEST(TexelsCarriedRigidly, ATurnCarriesPushesPastTheSameBackFace) {
  const Carried c = check_carried(move_tee({2, 3, -1}, std::array<double, 4>{0, 0.25881905, 0, 0.96592583}), false);
  EXPECT_EQ(c.carried, c.moved);
  EXPECT_GT(c.carried_pushed, 0u);
}

TEST(TexelsCarriedRigidly, TexelsWithinReachOfOtherGeometryAreNot) {
  // Set down on the ground: its floor lies on the ground quad, the wall's top stays clear.
  const Carried c = check_carried(move_tee({0, 0, 0}));
  EXPECT_GT(c.carried.size(), 0u);
  EXPECT_LT(c.carried.size(), c.moved.size());
}

TEST(TexelsCarriedRigidly, ABoxWithoutTrianglesWithinReachKeepsNoTexel) {
  // The ground's box grown to hold the T before (2 m up) and after (3 m up), its quad still at y = 0:
  // by boxes alone nothing is carried; by the triangles within reach, all of it (each checked
  // against a fresh unocclude step in check_carried).
  const WorldBox spanning{{-10, -1, -10}, {10, 10, 10}};
  const Carried boxes_alone = check_carried(move_tee({2, 3, -1}), true, false, spanning);
  EXPECT_TRUE(boxes_alone.carried.empty());
  const Carried by_triangles = check_carried(move_tee({2, 3, -1}), true, true, spanning);
  EXPECT_GT(by_triangles.moved.size(), 100u);
  EXPECT_EQ(by_triangles.carried, by_triangles.moved);
  // Set down on the ground, the texels at its foot stay within reach of the quad's triangles.
  const Carried on_ground = check_carried(move_tee({0, 0, 0}), true, true, spanning);
  EXPECT_GT(on_ground.carried.size(), 0u);
  EXPECT_LT(on_ground.carried.size(), on_ground.moved.size());
}

TEST(TexelsCarriedRigidly, UniformScaleIsCarriedOtherScalesAreNot) {
  const Carried uniform = check_carried(move_tee({0, 3, 0}, std::nullopt, std::array<double, 3>{1.5, 1.5, 1.5}));
  EXPECT_EQ(uniform.carried, uniform.moved);
  EXPECT_GT(uniform.carried_pushed, 0u);
  EXPECT_TRUE(check_carried(move_tee({0, 3, 0}, std::nullopt, std::array<double, 3>{1, 2, 1})).carried.empty());
  EXPECT_TRUE(check_carried(move_tee({0, 3, 0}, std::nullopt, std::array<double, 3>{-1, 1, 1})).carried.empty());  // a mirror
}

}  // namespace
}  // namespace exitance
