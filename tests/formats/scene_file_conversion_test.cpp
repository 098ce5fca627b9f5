// The runtime side of scene.bin on a real rasterized scene (samples/cornell_room through the
// offline stage): the texel G-buffer codec (decode(encode(g)) == g bit for bit, encode(decode(r))
// == r, so decode(encode(.)) is idempotent bit for bit), the Scene <-> SceneFile conversion with
// the real GPU BVH builder and probe placement, and a textured, vertex-coloured, masked, image-sky
// version of the room that round-trips field by field and lights bit-identically on the CPU.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>

#include "byte_patching.h"
#include "exitance/bake/command/prepared_scene.h"
#include "exitance/bake/probes/probe_placement.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/texel_gbuffer_codec.h"
#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/cpu_reference_integrator.h"

namespace exitance {
namespace {

using test::expect_format_error;

const PreparedScene& cornell() {
  static const PreparedScene prepared = [] {
    Diagnostics diagnostics;
    // 24 texels per unit instead of the default 64: ~70k live texels keep each test under a second.
    AtlasSettings atlas;
    atlas.texel_density = 24;
    return prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/cornell_room.gltf", "0.1,0.2,0.3", atlas, diagnostics);
  }();
  return prepared;
}

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

// Every LiveTexel field, page size and coverage value bit for bit.
void expect_gbuffers_equal(const TexelGBuffer& a, const TexelGBuffer& b) {
  ASSERT_EQ(a.texels.size(), b.texels.size());
  size_t differing = 0;
  for (size_t i = 0; i < a.texels.size(); ++i) {
    const LiveTexel &x = a.texels[i], &y = b.texels[i];
    const bool same = x.page == y.page && x.x == y.x && x.y == y.y && x.instance == y.instance &&
                      x.triangle == y.triangle && same_bits(x.position, y.position) &&
                      same_bits(x.geometric_normal, y.geometric_normal) &&
                      same_bits(x.shading_normal, y.shading_normal) && same_bits(x.albedo, y.albedo) &&
                      std::bit_cast<uint32_t>(x.world_texel_size) == std::bit_cast<uint32_t>(y.world_texel_size);
    if (!same && ++differing <= 5) ADD_FAILURE() << "texel " << i << " differs";
  }
  EXPECT_EQ(differing, 0u);
  ASSERT_EQ(a.pages.size(), b.pages.size());
  for (size_t p = 0; p < a.pages.size(); ++p) {
    ASSERT_EQ(a.pages[p].width, b.pages[p].width);
    ASSERT_EQ(a.pages[p].height, b.pages[p].height);
    ASSERT_EQ(a.pages[p].coverage.size(), b.pages[p].coverage.size());
    EXPECT_EQ(std::memcmp(a.pages[p].coverage.data(), b.pages[p].coverage.data(), a.pages[p].coverage.size() * 4), 0)
        << "page " << p << " coverage";
  }
  EXPECT_EQ(a.skipped_texels, b.skipped_texels);
}

void expect_records_equal(const formats::TexelGBufferRecords& a, const formats::TexelGBufferRecords& b) {
  ASSERT_EQ(a.pages.size(), b.pages.size());
  for (size_t p = 0; p < a.pages.size(); ++p)
    EXPECT_EQ(std::tie(a.pages[p].width, a.pages[p].height, a.pages[p].live_texels),
              std::tie(b.pages[p].width, b.pages[p].height, b.pages[p].live_texels));
  ASSERT_EQ(a.texels.size(), b.texels.size());
  size_t differing = 0;
  for (size_t i = 0; i < a.texels.size(); ++i) {
    const formats::TexelRecord &x = a.texels[i], &y = b.texels[i];
    const bool same = x.triangle == y.triangle && x.x == y.x && x.y == y.y &&
                      std::bit_cast<uint32_t>(x.b1) == std::bit_cast<uint32_t>(y.b1) &&
                      std::bit_cast<uint32_t>(x.b2) == std::bit_cast<uint32_t>(y.b2);
    if (!same) ++differing;
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(a.triangle_texel_size, b.triangle_texel_size);
  ASSERT_EQ(a.partial_coverage.size(), b.partial_coverage.size());
  for (size_t i = 0; i < a.partial_coverage.size(); ++i)
    EXPECT_EQ(std::tie(a.partial_coverage[i].texel, a.partial_coverage[i].coverage),
              std::tie(b.partial_coverage[i].texel, b.partial_coverage[i].coverage));
  ASSERT_EQ(a.moved.size(), b.moved.size());
  for (size_t i = 0; i < a.moved.size(); ++i)
    EXPECT_EQ(std::tie(a.moved[i].texel, a.moved[i].position), std::tie(b.moved[i].texel, b.moved[i].position));
}

TEST(TexelGBufferCodec, DecodeOfEncodeReproducesTheGBufferBitForBit) {
  const PreparedScene& p = cornell();
  ASSERT_GT(p.gbuffer.texels.size(), 1000u);
  const formats::TexelGBufferRecords records = encode_texel_gbuffer(p.gbuffer, p.scene, p.layout);
  expect_gbuffers_equal(p.gbuffer, decode_texel_gbuffer(records, p.scene));

  // The moved table holds exactly the texels unocclude moved: compare with the raster alone,
  // which needs no table at all.
  Diagnostics diagnostics;
  const TexelGBuffer raster = rasterize_texel_gbuffer(p.scene, p.layout, "cornell_room.gltf", diagnostics);
  ASSERT_EQ(raster.texels.size(), p.gbuffer.texels.size());
  std::vector<uint32_t> unoccluded;
  for (size_t i = 0; i < raster.texels.size(); ++i)
    if (!same_bits(raster.texels[i].position, p.gbuffer.texels[i].position)) unoccluded.push_back(uint32_t(i));
  EXPECT_GT(unoccluded.size(), 0u);
  ASSERT_EQ(records.moved.size(), unoccluded.size());
  for (size_t k = 0; k < unoccluded.size(); ++k) EXPECT_EQ(records.moved[k].texel, unoccluded[k]);
  const formats::TexelGBufferRecords raster_records = encode_texel_gbuffer(raster, p.scene, p.layout);
  EXPECT_TRUE(raster_records.moved.empty());
  expect_gbuffers_equal(raster, decode_texel_gbuffer(raster_records, p.scene));
  std::printf("cornell_room: %zu live texels on %zu pages, %zu partly covered, %zu moved by unocclude\n",
              p.gbuffer.texels.size(), p.gbuffer.pages.size(), records.partial_coverage.size(), unoccluded.size());
}

TEST(TexelGBufferCodec, EncodeOfDecodeGivesTheSameRecords) {
  const PreparedScene& p = cornell();
  const formats::TexelGBufferRecords once = encode_texel_gbuffer(p.gbuffer, p.scene, p.layout);
  const TexelGBuffer decoded = decode_texel_gbuffer(once, p.scene);
  const formats::TexelGBufferRecords twice = encode_texel_gbuffer(decoded, p.scene, p.layout);
  expect_records_equal(once, twice);
  expect_gbuffers_equal(decoded, decode_texel_gbuffer(twice, p.scene));
}

TEST(TexelGBufferCodec, RefusesGBuffersItCannotStore) {
  const PreparedScene& p = cornell();
  auto refused = [&](void (*edit)(TexelGBuffer&, const Scene&), const char* expected) {
    TexelGBuffer g = p.gbuffer;
    edit(g, p.scene);
    expect_format_error([&] { encode_texel_gbuffer(g, p.scene, p.layout); }, expected);
  };
  refused([](TexelGBuffer& g, const Scene&) { g.pages[0].width = 70000; }, "page 0: size 70000");
  refused([](TexelGBuffer& g, const Scene& s) { g.texels[5].triangle = uint32_t(s.triangle_count()); },
          "texel 5: triangle");
  refused([](TexelGBuffer& g, const Scene&) { g.texels[5].instance += 1; }, "texel 5: instance");
  refused([](TexelGBuffer& g, const Scene&) { g.texels[7].geometric_normal.x += 0.5f; },
          "texel 7: geometric normal is not its triangle's");
  refused([](TexelGBuffer& g, const Scene&) { g.texels[8].shading_normal.y += 1e-3f; },
          "texel 8: shading normal or albedo is not what its triangle gives");
  refused([](TexelGBuffer& g, const Scene&) { g.texels[8].albedo.z *= 0.5f; },
          "texel 8: shading normal or albedo is not what its triangle gives");
  refused([](TexelGBuffer& g, const Scene&) { std::swap(g.texels[3], g.texels[4]); }, "not in Morton order");
  refused([](TexelGBuffer& g, const Scene&) { g.texels[2].x = uint32_t(g.pages[0].width); }, "lies outside its page");
  refused(
      [](TexelGBuffer& g, const Scene&) {
        const LiveTexel& t = g.texels[9];
        g.pages[t.page].coverage[size_t(t.y) * size_t(g.pages[t.page].width) + t.x] = 0;
      },
      "texel 9: coverage 0.000000 is not in (0, 1]");
  refused(
      [](TexelGBuffer& g, const Scene&) {
        const LiveTexel& t = g.texels[9];
        g.pages[t.page].coverage[size_t(t.y) * size_t(g.pages[t.page].width) + t.x] = 1.5f;
      },
      "texel 9: coverage 1.500000 is not in (0, 1]");
  refused([](TexelGBuffer& g, const Scene&) { g.texels.pop_back(); }, "has coverage but is not live");
  refused(
      [](TexelGBuffer& g, const Scene&) {
        for (size_t i = 1; i < g.texels.size(); ++i)
          if (g.texels[i].triangle == g.texels[0].triangle) {
            g.texels[i].world_texel_size *= 2;
            return;
          }
      },
      "world texel size differs from that of other texels of triangle");
}

struct ConvertedCornell {
  formats::SceneBvh bvh;
  formats::ProbeGrid probes;
  formats::SceneFile file;
  std::vector<uint8_t> bytes;
};

const ConvertedCornell& converted() {
  static const ConvertedCornell c = [] {
    const PreparedScene& p = cornell();
    ConvertedCornell out;
    out.bvh = to_scene_bvh(build_bvh4(p.scene));
    const EmbreeScene embree(p.scene);
    out.probes = place_probes(p.scene, embree, nullptr, ProbePlacementSettings{}).grid;
    out.file = make_scene_file(p.scene, p.gbuffer, p.layout, &out.probes, out.bvh);
    out.bytes = formats::encode_scene(out.file);
    return out;
  }();
  return c;
}

TEST(SceneFileConversion, SceneRoundTripsThroughTheFile) {
  const PreparedScene& p = cornell();
  const ConvertedCornell& c = converted();
  const formats::SceneFile file = formats::read_scene(c.bytes.data(), c.bytes.size(), "scene.bin");
  const PersistedScene back = restore_scene(file);
  const Scene &a = p.scene, &b = back.scene;

  auto same_vec3s = [](const std::vector<Vec3>& x, const std::vector<Vec3>& y) {
    return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(Vec3)) == 0);
  };
  auto same_vec2s = [](const std::vector<Vec2>& x, const std::vector<Vec2>& y) {
    return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(Vec2)) == 0);
  };
  EXPECT_TRUE(same_vec3s(a.positions, b.positions));
  EXPECT_TRUE(same_vec3s(a.normals, b.normals));
  EXPECT_TRUE(same_vec2s(a.uv0, b.uv0));
  EXPECT_TRUE(same_vec2s(a.lightmap_uv, b.lightmap_uv));
  EXPECT_EQ(a.triangle_material, b.triangle_material);
  EXPECT_EQ(a.triangle_instance, b.triangle_instance);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) {
    EXPECT_EQ(a.materials[i].name, b.materials[i].name);
    EXPECT_TRUE(same_bits(a.materials[i].base_color, b.materials[i].base_color));
    EXPECT_EQ(a.materials[i].metallic, b.materials[i].metallic);
    EXPECT_TRUE(same_bits(a.materials[i].emission, b.materials[i].emission));
    EXPECT_EQ(a.materials[i].double_sided, b.materials[i].double_sided);
    EXPECT_EQ(b.materials[i].base_color_texture.texture, -1);
  }
  ASSERT_EQ(a.instances.size(), b.instances.size());
  for (size_t i = 0; i < a.instances.size(); ++i) {
    const Instance &x = a.instances[i], &y = b.instances[i];
    EXPECT_EQ(std::tie(x.node, x.name, x.mesh, x.first_triangle, x.triangle_count, x.world),
              std::tie(y.node, y.name, y.mesh, y.first_triangle, y.triangle_count, y.world));
    const InstanceRect &r = p.layout.rects[i], &s = back.atlas.rects[i];
    EXPECT_EQ(std::tie(r.page, r.x, r.y, r.width, r.height), std::tie(s.page, s.x, s.y, s.width, s.height));
    EXPECT_EQ(std::memcmp(r.scale_offset, s.scale_offset, sizeof(r.scale_offset)), 0);
  }
  EXPECT_EQ(back.atlas.page_sizes, p.layout.page_sizes);
  EXPECT_EQ(back.atlas.texel_density, p.layout.texel_density);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  ASSERT_FALSE(a.nodes.empty());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const SceneNode &x = a.nodes[i], &y = b.nodes[i];
    EXPECT_EQ(std::tie(x.name, x.parent, x.mesh, x.light, x.camera, x.in_scene, x.has_matrix, x.translation, x.rotation,
                       x.scale, x.matrix),
              std::tie(y.name, y.parent, y.mesh, y.light, y.camera, y.in_scene, y.has_matrix, y.translation, y.rotation,
                       y.scale, y.matrix));
  }
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    const PunctualLight &x = a.lights[i], &y = b.lights[i];
    EXPECT_EQ(std::tie(x.name, x.node, x.type, x.cos_inner, x.cos_outer),
              std::tie(y.name, y.node, y.type, y.cos_inner, y.cos_outer));
    EXPECT_TRUE(same_bits(x.position, y.position) && same_bits(x.direction, y.direction) &&
                same_bits(x.intensity, y.intensity));
  }
  EXPECT_EQ(a.cameras.size(), b.cameras.size());
  EXPECT_TRUE(same_bits(a.sky.constant, b.sky.constant));
  EXPECT_EQ(b.sky.constant.z, 0.3f);

  expect_gbuffers_equal(p.gbuffer, back.gbuffer);

  ASSERT_TRUE(back.has_probe_grid());
  EXPECT_EQ(back.probes.counts, c.probes.counts);
  EXPECT_EQ(back.probes.origin, c.probes.origin);
  EXPECT_EQ(back.probes.spacing, c.probes.spacing);
  ASSERT_EQ(back.probes.probes.size(), c.probes.probes.size());
  for (size_t i = 0; i < c.probes.probes.size(); ++i) {
    EXPECT_EQ(back.probes.probes[i].position, c.probes.probes[i].position);
    EXPECT_EQ(back.probes.probes[i].state, c.probes.probes[i].state);
  }
  ASSERT_EQ(back.bvh.nodes.size(), c.bvh.nodes.size());
  EXPECT_EQ(std::memcmp(back.bvh.nodes.data(), c.bvh.nodes.data(), c.bvh.nodes.size() * sizeof(formats::BvhNodeRecord)),
            0);
  EXPECT_EQ(back.bvh.leaf_triangles, c.bvh.leaf_triangles);
  EXPECT_EQ(back.bvh.stack_entries, c.bvh.stack_entries);
  EXPECT_EQ(back.bvh.depth, c.bvh.depth);

  // Writing what was restored gives the same bytes: a relight that re-saves the bundle is stable.
  const formats::SceneFile again =
      make_scene_file(back.scene, back.gbuffer, back.atlas, back.has_probe_grid() ? &back.probes : nullptr, back.bvh);
  EXPECT_EQ(formats::encode_scene(again), c.bytes);
}

TEST(SceneFileConversion, TheBvh4RoundTripsThroughItsRecords) {
  const PreparedScene& p = cornell();
  const Bvh4 gpu = build_bvh4(p.scene);
  const formats::SceneBvh& records = converted().bvh;
  EXPECT_EQ(records.leaf_triangles.size(), p.scene.triangle_count());
  const Bvh4 back = to_bvh4(records);
  ASSERT_EQ(back.nodes.size(), gpu.nodes.size());
  EXPECT_EQ(std::memcmp(back.nodes.data(), gpu.nodes.data(), gpu.nodes.size() * sizeof(Bvh4Node)), 0);
  EXPECT_EQ(back.leaf_triangles, gpu.leaf_triangles);
  EXPECT_EQ(back.stack_entries, gpu.stack_entries);
  EXPECT_EQ(back.depth, gpu.depth);
}

TEST(SceneFileConversion, RefusesWhatItCannotStore) {
  const PreparedScene& p = cornell();
  const formats::SceneBvh& bvh = converted().bvh;
  AtlasLayout short_layout = p.layout;
  short_layout.rects.pop_back();
  expect_format_error([&] { make_scene_file(p.scene, p.gbuffer, short_layout, nullptr, bvh); }, "rectangles for");
  Scene bad_colours = p.scene;
  bad_colours.vertex_color.assign(3, Vec3{1, 1, 1});
  bad_colours.vertex_alpha.assign(3, 1.0f);
  expect_format_error([&] { make_scene_file(bad_colours, p.gbuffer, p.layout, nullptr, bvh); },
                      "COLOR_0: vertex colours and alphas do not hold one entry per corner");
  // A corrupt BVH is caught by the writer's validation.
  formats::SceneFile file = make_scene_file(p.scene, p.gbuffer, p.layout, nullptr, bvh);
  file.bvh.nodes[0].child[0] = uint32_t(file.bvh.nodes.size());
  expect_format_error([&] { formats::encode_scene(file); }, "bvh node 0: child 0 index");
}

Texture make_texture(int width, int height, bool with_alpha, float seed) {
  Texture t;
  t.width = width;
  t.height = height;
  for (int i = 0; i < width * height * 3; ++i) t.rgb.push_back(0.5f + 0.45f * std::sin(seed * float(i + 1)));
  if (with_alpha)
    for (int i = 0; i < width * height; ++i) t.alpha.push_back(0.5f + 0.5f * std::cos(seed * float(3 * i + 1)));
  return t;
}

// The room with what only format version 2 stores: a base colour texture with alpha (clamped, read
// through TEXCOORD_1 with a transform) on a MASK material, an emissive texture on the lamp, a BLEND
// material, COLOR_0 on every corner and an environment-map sky; the G-buffer rasterized from it (its
// albedo is the textured, vertex-coloured one).
struct TexturedCornell {
  Scene scene;
  AtlasLayout layout;
  TexelGBuffer gbuffer;
  formats::SceneBvh bvh;
  std::vector<uint8_t> bytes;
};

const TexturedCornell& textured_cornell() {
  static const TexturedCornell c = [] {
    TexturedCornell out;
    out.scene = cornell().scene;
    out.layout = cornell().layout;
    Scene& s = out.scene;
    s.textures.push_back(make_texture(16, 8, true, 0.37f));
    s.textures.back().wrap_s = Texture::Wrap::ClampToEdge;
    s.textures.back().wrap_t = Texture::Wrap::MirroredRepeat;
    s.textures.push_back(make_texture(4, 4, false, 1.3f));
    int emissive = -1;
    for (size_t i = 0; i < s.materials.size(); ++i)
      if (max_component(s.materials[i].emission) > 0) emissive = int(i);
    EXPECT_GE(emissive, 0);
    Material& walls = s.materials[emissive == 0 ? 1 : 0];
    walls.base_color_texture.texture = 0;
    walls.base_color_texture.transform = {{0.25f, -0.5f}, 0.3f, {3.0f, 2.0f}, 1};
    walls.alpha_mode = Material::AlphaMode::Mask;
    walls.alpha_cutoff = 0.2f;
    walls.base_alpha = 0.9f;
    s.materials[size_t(emissive)].emissive_texture.texture = 1;
    if (s.materials.size() > 2) s.materials.back().alpha_mode = Material::AlphaMode::Blend;
    for (size_t c = 0; c < s.positions.size(); ++c) {
      s.vertex_color.push_back(Vec3{0.6f + 0.4f * float(c % 3) / 2, 1.0f, 0.7f + 0.1f * float(c % 4)});
      s.vertex_alpha.push_back(c % 5 == 0 ? 0.8f : 1.0f);
    }
    s.sky.environment = make_texture(32, 16, false, 0.011f);
    Diagnostics diagnostics;
    out.gbuffer = rasterize_texel_gbuffer(s, out.layout, "cornell_room (textured)", diagnostics);
    out.bvh = to_scene_bvh(build_bvh4(s));
    out.bytes = formats::encode_scene(make_scene_file(s, out.gbuffer, out.layout, nullptr, out.bvh));
    return out;
  }();
  return c;
}

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  // Bit for bit (-0 and NaN payloads included); empty vectors may hold null data, which memcmp must not see.
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

void expect_same_texture(const Texture& a, const Texture& b) {
  EXPECT_EQ(std::tie(a.width, a.height, a.wrap_s, a.wrap_t), std::tie(b.width, b.height, b.wrap_s, b.wrap_t));
  EXPECT_TRUE(same_floats(a.rgb, b.rgb));
  EXPECT_TRUE(same_floats(a.alpha, b.alpha));
}

void expect_same_binding(const TextureBinding& a, const TextureBinding& b) {
  EXPECT_EQ(a.texture, b.texture);
  EXPECT_EQ(a.transform.tex_coord, b.transform.tex_coord);
  const float x[5] = {a.transform.offset.x, a.transform.offset.y, a.transform.rotation, a.transform.scale.x,
                      a.transform.scale.y};
  const float y[5] = {b.transform.offset.x, b.transform.offset.y, b.transform.rotation, b.transform.scale.x,
                      b.transform.scale.y};
  EXPECT_EQ(std::memcmp(x, y, sizeof(x)), 0);
}

TEST(SceneFileConversion, TexturedSceneRoundTripsFieldByField) {
  const TexturedCornell& c = textured_cornell();
  const formats::SceneFile file = formats::read_scene(c.bytes.data(), c.bytes.size(), "scene.bin");
  EXPECT_EQ(file.textures.size(), 2u);
  const PersistedScene back = restore_scene(file);
  const Scene &a = c.scene, &b = back.scene;
  ASSERT_EQ(a.textures.size(), b.textures.size());
  for (size_t i = 0; i < a.textures.size(); ++i) expect_same_texture(a.textures[i], b.textures[i]);
  ASSERT_TRUE(b.sky.has_environment());
  expect_same_texture(a.sky.environment, b.sky.environment);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) {
    const Material &x = a.materials[i], &y = b.materials[i];
    expect_same_binding(x.base_color_texture, y.base_color_texture);
    expect_same_binding(x.emissive_texture, y.emissive_texture);
    EXPECT_EQ(std::tie(x.alpha_mode, x.alpha_cutoff, x.base_alpha), std::tie(y.alpha_mode, y.alpha_cutoff, y.base_alpha));
  }
  ASSERT_EQ(a.vertex_color.size(), b.vertex_color.size());
  EXPECT_EQ(std::memcmp(a.vertex_color.data(), b.vertex_color.data(), a.vertex_color.size() * sizeof(Vec3)), 0);
  EXPECT_TRUE(same_floats(a.vertex_alpha, b.vertex_alpha));
  // The G-buffer's albedo (textured, vertex-coloured) comes back bit for bit from the stored textures.
  expect_gbuffers_equal(c.gbuffer, back.gbuffer);
  const formats::SceneFile again =
      make_scene_file(back.scene, back.gbuffer, back.atlas, nullptr, back.bvh);
  EXPECT_EQ(formats::encode_scene(again), c.bytes);
  std::printf("textured cornell_room scene.bin: %zu bytes\n", c.bytes.size());
}

// Version 3 through the runtime types: a normal texture (binding with a transform, a scale) and per-
// corner tangent frames (both signs, zero tangents on another material's corners) come back bit for
// bit, and the file re-encodes to the same bytes; tangents of the wrong length are refused.
TEST(SceneFileConversion, NormalMapAndTangentsRoundTripThroughTheRuntimeScene) {
  Scene s = cornell().scene;
  s.textures.push_back(make_texture(4, 2, false, 0.77f));
  Material& walls = s.materials[0];
  walls.normal_texture.texture = int(s.textures.size() - 1);
  walls.normal_texture.transform = {{0.5f, 0.25f}, -0.7f, {2.0f, 4.0f}, 1};
  walls.normal_scale = 0.625f;
  for (size_t c = 0; c < s.positions.size(); ++c) {
    const bool mapped = s.triangle_material[c / 3] == 0;
    s.tangents.push_back(mapped ? normalize(Vec3{1.0f, 0.1f * float(c % 7), -0.2f}) : Vec3(0));
    s.tangent_signs.push_back(c % 3 == 2 ? -1.0f : 1.0f);
  }
  const AtlasLayout& layout = cornell().layout;
  const formats::SceneBvh bvh = to_scene_bvh(build_bvh4(s));
  const std::vector<uint8_t> bytes = formats::encode_scene(make_scene_file(s, cornell().gbuffer, layout, nullptr, bvh));
  const PersistedScene back = restore_scene(formats::read_scene(bytes.data(), bytes.size(), "scene.bin"));
  const Scene& b = back.scene;
  ASSERT_EQ(b.materials.size(), s.materials.size());
  for (size_t i = 0; i < s.materials.size(); ++i) {
    expect_same_binding(s.materials[i].normal_texture, b.materials[i].normal_texture);
    EXPECT_EQ(std::bit_cast<uint32_t>(s.materials[i].normal_scale), std::bit_cast<uint32_t>(b.materials[i].normal_scale));
  }
  ASSERT_EQ(b.tangents.size(), s.tangents.size());
  EXPECT_EQ(std::memcmp(b.tangents.data(), s.tangents.data(), s.tangents.size() * sizeof(Vec3)), 0);
  EXPECT_TRUE(same_floats(b.tangent_signs, s.tangent_signs));
  EXPECT_EQ(formats::encode_scene(make_scene_file(b, back.gbuffer, back.atlas, nullptr, back.bvh)), bytes);
  Scene short_tangents = s;
  short_tangents.tangent_signs.pop_back();
  EXPECT_THROW(make_scene_file(short_tangents, cornell().gbuffer, layout, nullptr, bvh), formats::FormatError);
}

// What the CPU reference lights from the restored scene is what it lights from the source scene,
// bit for bit, at the same seed; without the stored textures it is not (the test can fail).
TEST(SceneFileConversion, RestoredTexturedSceneLightsBitIdentically) {
  const TexturedCornell& c = textured_cornell();
  const PersistedScene back = restore_scene(formats::read_scene(c.bytes.data(), c.bytes.size(), "scene.bin"));
  IntegratorSettings settings;
  settings.spp = 2;
  settings.seed = 7;
  const LightmapEstimate source = CpuReferenceIntegrator(c.scene).bake(c.gbuffer, settings);
  const LightmapEstimate restored = CpuReferenceIntegrator(back.scene).bake(back.gbuffer, settings);
  ASSERT_EQ(source.texels.size(), restored.texels.size());
  size_t differing = 0;
  for (size_t i = 0; i < source.texels.size(); ++i)
    if (!same_bits(source.mean_total(i), restored.mean_total(i))) ++differing;
  EXPECT_EQ(differing, 0u);
  Scene untextured = back.scene;
  untextured.textures.clear();
  untextured.sky.environment = Texture{};
  for (Material& m : untextured.materials) m.base_color_texture.texture = m.emissive_texture.texture = -1;
  const LightmapEstimate plain = CpuReferenceIntegrator(untextured).bake(back.gbuffer, settings);
  size_t changed = 0;
  for (size_t i = 0; i < source.texels.size(); ++i)
    if (!same_bits(source.mean_total(i), plain.mean_total(i))) ++changed;
  EXPECT_GT(changed, source.texels.size() / 2);
  std::printf("[textured cornell] %zu texels bit-identical; %zu differ without the textures\n",
              source.texels.size() - differing, changed);
}

TEST(SceneFileConversion, FileWithoutProbesRestoresNoGrid) {
  const PreparedScene& p = cornell();
  const formats::SceneFile file = make_scene_file(p.scene, p.gbuffer, p.layout, nullptr, converted().bvh);
  const std::vector<uint8_t> bytes = formats::encode_scene(file);
  const PersistedScene back = restore_scene(formats::read_scene(bytes.data(), bytes.size(), "scene.bin"));
  EXPECT_FALSE(back.has_probe_grid());
  EXPECT_EQ(back.probes.counts, (std::array<uint32_t, 3>{0, 0, 0}));
  std::printf("cornell_room scene.bin: %zu bytes (%zu with probe positions)\n", bytes.size(), converted().bytes.size());
}

}  // namespace
}  // namespace exitance
