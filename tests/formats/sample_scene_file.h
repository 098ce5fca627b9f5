// A small but complete scene.bin in memory, built by hand so every field has a known, distinct
// value: 4 triangles in 2 instances on 2 pages, 3 materials, 5 nodes (TRS, matrix, a node outside
// the scene), 2 cameras, 3 lights, 5 live texels (3 partly covered, 1 moved), a 2 x 1 x 2 probe
// grid and a BVH of two inner nodes. Shared by the scene.bin tests and the fuzzer's seed writer.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include "exitance/formats/scene_file.h"

namespace exitance::test {

// The BVH child box of a set of triangles (exact float min / max of their corners).
inline void set_child_box(formats::BvhNodeRecord& node, int child, const formats::SceneFile& s,
                          std::initializer_list<uint32_t> triangles) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t t : triangles)
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], s.triangles.positions[3 * t + size_t(k)][size_t(a)]);
        hi[a] = std::max(hi[a], s.triangles.positions[3 * t + size_t(k)][size_t(a)]);
      }
  node.lo_x[child] = lo[0], node.lo_y[child] = lo[1], node.lo_z[child] = lo[2];
  node.hi_x[child] = hi[0], node.hi_y[child] = hi[1], node.hi_z[child] = hi[2];
}

inline void set_empty_children(formats::BvhNodeRecord& node) {
  for (int c = 0; c < 4; ++c) {
    node.child[c] = formats::kSceneBvhEmptyChild;
    node.lo_x[c] = node.lo_y[c] = node.lo_z[c] = 1.0f;
    node.hi_x[c] = node.hi_y[c] = node.hi_z[c] = -1.0f;
  }
}

inline uint32_t leaf_word(uint32_t first, uint32_t count) {
  return formats::kSceneBvhLeafBit | (first << 2) | (count - 1);
}

inline formats::SceneFile make_sample_scene_file() {
  using namespace formats;
  SceneFile s;
  // Instance 0: a floor quad (triangles 0, 1) at y = 0; instance 1: a wall quad (2, 3) at z = -2.
  const Float3 floor[4] = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  const Float3 wall[4] = {{-1, 0, -2}, {1, 0, -2}, {1, 2, -2}, {-1, 2, -2}};
  const int corners[2][3] = {{0, 2, 1}, {0, 3, 2}};
  for (int quad = 0; quad < 2; ++quad)
    for (const auto& tri : corners) {
      for (int k : tri) {
        const Float3 p = quad == 0 ? floor[k] : wall[k];
        s.triangles.positions.push_back(p);
        s.triangles.normals.push_back(quad == 0 ? Float3{0, 1, 0} : Float3{0, 0.6f, 0.8f});
        s.triangles.lightmap_uv.push_back({(p[0] + 1) * 0.5f, quad == 0 ? (p[2] + 1) * 0.5f : p[1] * 0.5f});
        s.triangles.uv0.push_back({float(k) * 0.25f, -float(k)});
      }
      s.triangles.material.push_back(uint32_t(quad == 0 ? 0 : s.triangles.count() % 2 + 1));
      s.triangles.instance.push_back(uint32_t(quad));
    }

  auto material = [](const char* name, Float3 base_color, float metallic, Float3 emission, bool double_sided) {
    MaterialRecord m;
    m.name = name;
    m.base_color = base_color;
    m.metallic = metallic;
    m.emission = emission;
    m.double_sided = double_sided;
    return m;
  };
  MaterialRecord white = material("White", {0.8f, 0.8f, 0.8f}, 0.0f, {0, 0, 0}, false);
  MaterialRecord lamp = material("Lamp panel", {1, 1, 1}, 0.25f, {4, 3.5f, 3}, true);
  MaterialRecord dark = material("", {0.05f, 0.1f, 0.2f}, 1.0f, {0, 0, 0}, false);
  s.materials = {white, lamp, dark};

  // Nodes: 0 "root" (TRS) -> 1 "Floor" (mesh 0), 2 "Wall" (matrix, mesh 1) -> 3 "Sun" (light,
  // camera); 4 "Unused" is outside the default scene.
  s.nodes.resize(5);
  s.nodes[0].name = "root";
  s.nodes[0].in_scene = true;
  s.nodes[0].translation = {0.5, -1e-300, 3};
  s.nodes[0].rotation = {0, 0.7071067811865476, 0, 0.7071067811865476};
  s.nodes[0].scale = {2, 2, 2};
  s.nodes[1].name = "Floor";
  s.nodes[1].parent = 0;
  s.nodes[1].mesh = 0;
  s.nodes[1].in_scene = true;
  s.nodes[2].name = "Wall";
  s.nodes[2].parent = 0;
  s.nodes[2].mesh = 1;
  s.nodes[2].in_scene = true;
  s.nodes[2].has_matrix = true;
  s.nodes[2].matrix = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.1, 0.2, -0.3, 1};
  s.nodes[3].name = "Sun";
  s.nodes[3].parent = 2;
  s.nodes[3].light = 2;
  s.nodes[3].camera = 0;
  s.nodes[3].in_scene = true;
  s.nodes[4].name = "Unused \xc3\xa9";
  s.nodes[4].mesh = 7;

  s.instances.resize(2);
  s.instances[0] = {"Floor", 1, 0, 0, 2, kIdentityMatrix, 0, 1, 1, 6, 2, {0.75f, 0.5f, 0.125f, 0.25f}};
  s.instances[1] = {"Wall", 2, 1, 2, 2, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.1, 0.2, -0.3, 1},
                    1,      0, 0, 4, 4, {1, 1, 0, 0}};
  s.nodes[0].camera = 1;
  s.cameras.resize(2);
  s.cameras[0] = {"Sun view", 3, CameraType::Perspective, 0.8f, 1.5f, 0, 0, 0.05f, 0};
  s.cameras[1] = {"Top", 0, CameraType::Orthographic, 0, 0, 4, 3, 0, 100};
  s.lights.resize(3);
  s.lights[0] = {"Bulb", -1, LightType::Point, {0, 1.5f, 0}, {0, 0, -1}, {10, 9, 8}, 1, 0};
  s.lights[1] = {"Spot", -1, LightType::Spot, {0.5f, 1.8f, -0.5f}, {0, -1, 0}, {20, 20, 20}, 0.9f, 0.7f};
  s.lights[2] = {"Sun", 3, LightType::Directional, {0, 0, 0}, {0.6f, -0.8f, 0}, {3, 3, 2.5f}, 1, 0};
  s.sky = {0.1f, 0.2f, 0.4f};
  s.texel_density = 3.5f;

  s.texels.pages = {{8, 4, 3}, {4, 4, 2}};
  // Page 0: Morton codes (1,1)=3, (2,1)=6, (3,2)=13; page 1: (0,0)=0, (3,3)=15.
  s.texels.texels = {{0, 1, 1, 0.25f, 0.5f},
                     {1, 2, 1, 0.0f, 1.0f},
                     {0, 3, 2, 0.125f, 0.125f},
                     {2, 0, 0, 1.0f / 3.0f, 1.0f / 3.0f},
                     {3, 3, 3, 0.5f, 0.25f}};
  s.texels.triangle_texel_size = {0.3f, 0.3f, 0.5f, std::numeric_limits<float>::denorm_min()};
  s.texels.partial_coverage = {{1, 0.6f}, {2, 1e-3f}, {4, 0.25f}};
  s.texels.moved = {{3, {-0.9f, 0.1f, -1.999f}}};

  s.probes = ProbeGrid{};
  s.probes.origin = {-1, 0.5f, -1};
  s.probes.spacing = {2, 1, 2};
  s.probes.counts = {2, 1, 2};
  s.probes.probes.resize(4);
  for (size_t i = 0; i < 4; ++i) {
    s.probes.probes[i].position = {float(i) - 1, 0.5f, float(i) * 0.5f};
    s.probes.probes[i].state = ProbeState(i);
  }

  // BVH: root -> (node 1 -> leaves {slot 0}, {slot 1}), leaf {slots 2, 3}.
  s.bvh.nodes.resize(2);
  set_empty_children(s.bvh.nodes[0]);
  set_empty_children(s.bvh.nodes[1]);
  s.bvh.leaf_triangles = {1, 0, 3, 2};
  s.bvh.nodes[0].child[0] = 1;
  set_child_box(s.bvh.nodes[0], 0, s, {0, 1});
  s.bvh.nodes[0].child[1] = leaf_word(2, 2);
  set_child_box(s.bvh.nodes[0], 1, s, {2, 3});
  s.bvh.nodes[1].child[0] = leaf_word(0, 1);
  set_child_box(s.bvh.nodes[1], 0, s, {1});
  s.bvh.nodes[1].child[2] = leaf_word(1, 1);
  set_child_box(s.bvh.nodes[1], 2, s, {0});
  s.bvh.stack_entries = 4;  // root pushes 2, node 1 pushes 2
  s.bvh.depth = 2;
  return s;
}

// The sample plus everything only format version 2 stores: two textures (one with alpha, other wrap
// modes), a MASK material reading texture 1 through TEXCOORD_1 with a KHR_texture_transform, an
// emissive texture, a BLEND material, per-corner vertex colours and an environment-map sky.
inline formats::SceneFile make_textured_sample_scene_file() {
  using namespace formats;
  SceneFile s = make_sample_scene_file();
  TextureRecord albedo;
  albedo.width = 3;
  albedo.height = 2;
  albedo.wrap_s = TextureWrap::ClampToEdge;
  albedo.wrap_t = TextureWrap::MirroredRepeat;
  for (int i = 0; i < 18; ++i) albedo.rgb.push_back(0.05f * float(i));
  albedo.rgb[0] = -0.0f;  // the sign of zero must survive
  TextureRecord leaf;
  leaf.width = 2;
  leaf.height = 2;
  leaf.rgb = {0.2f, 0.7f, 0.1f, 0.3f, 0.6f, 0.2f, std::numeric_limits<float>::denorm_min(), 0.5f, 0.0f, 1.0f, 1.0f, 1.0f};
  leaf.alpha = {1.0f, 0.25f, 0.0f, 0.75f};
  s.textures = {albedo, leaf};
  MaterialRecord& white = s.materials[0];
  white.alpha_mode = AlphaMode::Mask;
  white.alpha_cutoff = 0.3f;
  white.base_alpha = 0.875f;
  white.base_color_texture = {1, 1, {0.25f, -0.5f}, 0.125f, {2.0f, 0.5f}};
  MaterialRecord& lamp = s.materials[1];
  lamp.emissive_texture = {0, 0, {0, 0}, 0, {1, 1}};
  lamp.base_color_texture = {0, 0, {1.5f, 0}, -3.0f, {1, -1}};
  s.materials[2].alpha_mode = AlphaMode::Blend;
  s.materials[2].base_alpha = 0.5f;
  for (size_t c = 0; c < s.triangles.positions.size(); ++c) {
    s.vertex_color.push_back({float(c % 3) * 0.5f, 1.0f, 0.25f * float(c % 5)});
    s.vertex_alpha.push_back(c % 4 == 0 ? 0.5f : 1.0f);
  }
  s.sky_environment.width = 4;
  s.sky_environment.height = 2;
  for (int i = 0; i < 24; ++i) s.sky_environment.rgb.push_back(i < 12 ? 1.5f + float(i) : 0.125f);
  return s;
}

// The textured sample plus what only format version 3 stores: a normal texture binding (with a
// transform and scale) and per-corner tangent frames (both handedness signs, a zero tangent).
inline formats::SceneFile make_normal_mapped_sample_scene_file() {
  formats::SceneFile s = make_textured_sample_scene_file();
  s.materials[0].normal_texture = {0, 1, {0.5f, -0.25f}, 0.375f, {1.0f, 2.0f}};
  s.materials[0].normal_scale = 0.625f;
  s.materials[2].normal_texture = {1, 0, {0, 0}, 0, {1, 1}};
  for (size_t c = 0; c < s.triangles.positions.size(); ++c) {
    s.tangents.push_back(c == 5 ? formats::Float3{0, 0, 0} : formats::Float3{c % 2 ? 1.0f : 0.0f, c % 2 ? 0.0f : 0.6f, c % 2 ? 0.0f : 0.8f});
    s.tangent_signs.push_back(c % 3 == 1 ? -1.0f : 1.0f);
  }
  return s;
}

}  // namespace exitance::test
