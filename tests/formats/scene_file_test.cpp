// scene.bin: exact round trips of every field, the documented byte layout, and refusal of every
// truncation, every single-byte corruption, other versions and structurally wrong files with right
// checksums (BVH links and boxes, texels, indices, non-finite numbers).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include <unistd.h>

#include "byte_patching.h"
#include "exitance/formats/scene_file.h"
#include "sample_scene_file.h"

namespace exitance::formats {
namespace {

using test::expect_format_error;
using test::put_f32;
using test::put_u32;
using test::refresh_checksums;

constexpr size_t kHeader = kSceneHeaderSize;

// Payload section offsets (scene_format.md, "Payload") for the sample's counts.
struct Offsets {
  size_t positions, normals, lightmap_uv, uv0, material, instance, texel_size, bvh_nodes, bvh_leaves, pages,
      texel_triangle, texel_xy, texel_barycentrics, partial_coverage, moved, probes, materials;
};
Offsets offsets_for(const SceneFile& s) {
  Offsets o{};
  const size_t t = s.triangles.count(), n = s.texels.texels.size();
  o.positions = kHeader;
  o.normals = o.positions + 36 * t;
  o.lightmap_uv = o.normals + 36 * t;
  o.uv0 = o.lightmap_uv + 24 * t;
  o.material = o.uv0 + 24 * t;
  o.instance = o.material + 4 * t;
  o.texel_size = o.instance + 4 * t;
  o.bvh_nodes = o.texel_size + 4 * t;
  o.bvh_leaves = o.bvh_nodes + 112 * s.bvh.nodes.size();
  o.pages = o.bvh_leaves + 4 * s.bvh.leaf_triangles.size();
  o.texel_triangle = o.pages + 12 * s.texels.pages.size();
  o.texel_xy = o.texel_triangle + 4 * n;
  o.texel_barycentrics = o.texel_xy + 4 * n;
  o.partial_coverage = o.texel_barycentrics + 8 * n;
  o.moved = o.partial_coverage + 8 * s.texels.partial_coverage.size();
  o.probes = o.moved + 16 * s.texels.moved.size();
  o.materials = o.probes + 16 * s.probes.probes.size();
  return o;
}
// Inside a 112-byte BVH node: plane p (lo.x, hi.x, lo.y, hi.y, lo.z, hi.z), child c.
size_t bvh_plane(const Offsets& o, size_t node, int plane, int child) {
  return o.bvh_nodes + 112 * node + size_t(16 * plane + 4 * child);
}
size_t bvh_child(const Offsets& o, size_t node, int child) { return o.bvh_nodes + 112 * node + 96 + size_t(4 * child); }

std::string fresh_directory(const std::string& name) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("exitance-scene-" + std::to_string(::getpid()) + "-" + name);
  std::filesystem::remove_all(path);
  std::filesystem::create_directories(path);
  return path.string();
}

const SceneFile& sample() {
  static const SceneFile s = test::make_sample_scene_file();
  return s;
}
const Offsets& sample_offsets() {
  static const Offsets o = offsets_for(sample());
  return o;
}
const std::vector<uint8_t>& sample_bytes() {
  static const std::vector<uint8_t> bytes = encode_scene(sample());
  return bytes;
}
const SceneFile& textured() {
  static const SceneFile s = test::make_textured_sample_scene_file();
  return s;
}
const std::vector<uint8_t>& textured_bytes() {
  static const std::vector<uint8_t> bytes = encode_scene(textured());
  return bytes;
}

SceneFile read(const std::vector<uint8_t>& bytes) { return read_scene(bytes.data(), bytes.size(), "scene.bin"); }

template <typename T>
void expect_same_bytes(const std::vector<T>& a, const std::vector<T>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  if (!a.empty()) {
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(T)), 0) << what;
  }
}

void expect_same_texture(const TextureRecord& a, const TextureRecord& b, const char* what) {
  EXPECT_EQ(std::tie(a.width, a.height, a.wrap_s, a.wrap_t), std::tie(b.width, b.height, b.wrap_s, b.wrap_t)) << what;
  expect_same_bytes(a.rgb, b.rgb, what);
  expect_same_bytes(a.alpha, b.alpha, what);
}

// Every field, bit for bit (floats by memcmp, so -0 and denormals count).
void expect_bitwise_equal(const SceneFile& a, const SceneFile& b) {
  expect_same_bytes(a.triangles.positions, b.triangles.positions, "positions");
  expect_same_bytes(a.triangles.normals, b.triangles.normals, "normals");
  expect_same_bytes(a.triangles.lightmap_uv, b.triangles.lightmap_uv, "lightmap_uv");
  expect_same_bytes(a.triangles.uv0, b.triangles.uv0, "uv0");
  EXPECT_EQ(a.triangles.material, b.triangles.material);
  EXPECT_EQ(a.triangles.instance, b.triangles.instance);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) {
    const MaterialRecord &x = a.materials[i], &y = b.materials[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.base_color, y.base_color);
    EXPECT_EQ(x.metallic, y.metallic);
    EXPECT_EQ(x.emission, y.emission);
    EXPECT_EQ(x.double_sided, y.double_sided);
    for (auto [u, v] : {std::pair{&x.base_color_texture, &y.base_color_texture},
                        std::pair{&x.emissive_texture, &y.emissive_texture}}) {
      EXPECT_EQ(std::tie(u->texture, u->tex_coord, u->offset, u->scale), std::tie(v->texture, v->tex_coord, v->offset, v->scale));
      EXPECT_EQ(std::bit_cast<uint32_t>(u->rotation), std::bit_cast<uint32_t>(v->rotation));
    }
    EXPECT_EQ(std::tie(x.alpha_mode, x.alpha_cutoff, x.base_alpha), std::tie(y.alpha_mode, y.alpha_cutoff, y.base_alpha));
    const TextureBindingRecord &u = x.normal_texture, &v = y.normal_texture;
    EXPECT_EQ(std::tie(u.texture, u.tex_coord, u.offset, u.scale), std::tie(v.texture, v.tex_coord, v.offset, v.scale));
    EXPECT_EQ(std::bit_cast<uint32_t>(u.rotation), std::bit_cast<uint32_t>(v.rotation));
    EXPECT_EQ(std::bit_cast<uint32_t>(x.normal_scale), std::bit_cast<uint32_t>(y.normal_scale));
  }
  ASSERT_EQ(a.textures.size(), b.textures.size());
  for (size_t i = 0; i < a.textures.size(); ++i) expect_same_texture(a.textures[i], b.textures[i], "texture");
  expect_same_texture(a.sky_environment, b.sky_environment, "sky environment");
  expect_same_bytes(a.vertex_color, b.vertex_color, "vertex colours");
  expect_same_bytes(a.vertex_alpha, b.vertex_alpha, "vertex alphas");
  expect_same_bytes(a.tangents, b.tangents, "tangents");
  expect_same_bytes(a.tangent_signs, b.tangent_signs, "tangent signs");
  ASSERT_EQ(a.instances.size(), b.instances.size());
  for (size_t i = 0; i < a.instances.size(); ++i) {
    const InstanceRecord &x = a.instances[i], &y = b.instances[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(std::tie(x.node, x.mesh, x.first_triangle, x.triangle_count, x.page, x.x, x.y, x.width, x.height),
              std::tie(y.node, y.mesh, y.first_triangle, y.triangle_count, y.page, y.x, y.y, y.width, y.height));
    EXPECT_EQ(std::memcmp(x.world.data(), y.world.data(), sizeof(x.world)), 0);
    EXPECT_EQ(x.scale_offset, y.scale_offset);
  }
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const NodeRecord &x = a.nodes[i], &y = b.nodes[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(std::tie(x.parent, x.mesh, x.light, x.camera, x.in_scene, x.has_matrix),
              std::tie(y.parent, y.mesh, y.light, y.camera, y.in_scene, y.has_matrix));
    EXPECT_EQ(std::memcmp(x.translation.data(), y.translation.data(), sizeof(x.translation)), 0);
    EXPECT_EQ(std::memcmp(x.rotation.data(), y.rotation.data(), sizeof(x.rotation)), 0);
    EXPECT_EQ(std::memcmp(x.scale.data(), y.scale.data(), sizeof(x.scale)), 0);
    EXPECT_EQ(std::memcmp(x.matrix.data(), y.matrix.data(), sizeof(x.matrix)), 0);
  }
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t i = 0; i < a.cameras.size(); ++i) {
    const CameraRecord &x = a.cameras[i], &y = b.cameras[i];
    EXPECT_EQ(std::tie(x.name, x.node, x.type, x.yfov, x.aspect_ratio, x.xmag, x.ymag, x.znear, x.zfar),
              std::tie(y.name, y.node, y.type, y.yfov, y.aspect_ratio, y.xmag, y.ymag, y.znear, y.zfar));
  }
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    const LightRecord &x = a.lights[i], &y = b.lights[i];
    EXPECT_EQ(std::tie(x.name, x.node, x.type, x.position, x.direction, x.intensity, x.cos_inner, x.cos_outer),
              std::tie(y.name, y.node, y.type, y.position, y.direction, y.intensity, y.cos_inner, y.cos_outer));
  }
  EXPECT_EQ(a.sky, b.sky);
  EXPECT_EQ(std::bit_cast<uint32_t>(a.texel_density), std::bit_cast<uint32_t>(b.texel_density));
  ASSERT_EQ(a.texels.pages.size(), b.texels.pages.size());
  for (size_t p = 0; p < a.texels.pages.size(); ++p)
    EXPECT_EQ(std::tie(a.texels.pages[p].width, a.texels.pages[p].height, a.texels.pages[p].live_texels),
              std::tie(b.texels.pages[p].width, b.texels.pages[p].height, b.texels.pages[p].live_texels));
  ASSERT_EQ(a.texels.texels.size(), b.texels.texels.size());
  for (size_t i = 0; i < a.texels.texels.size(); ++i) {
    const TexelRecord &x = a.texels.texels[i], &y = b.texels.texels[i];
    EXPECT_EQ(std::tie(x.triangle, x.x, x.y), std::tie(y.triangle, y.x, y.y)) << "texel " << i;
    EXPECT_EQ(std::bit_cast<uint32_t>(x.b1), std::bit_cast<uint32_t>(y.b1));
    EXPECT_EQ(std::bit_cast<uint32_t>(x.b2), std::bit_cast<uint32_t>(y.b2));
  }
  expect_same_bytes(a.texels.triangle_texel_size, b.texels.triangle_texel_size, "triangle texel sizes");
  ASSERT_EQ(a.texels.partial_coverage.size(), b.texels.partial_coverage.size());
  for (size_t i = 0; i < a.texels.partial_coverage.size(); ++i) {
    const PartialCoverageRecord &x = a.texels.partial_coverage[i], &y = b.texels.partial_coverage[i];
    EXPECT_EQ(std::tie(x.texel, x.coverage), std::tie(y.texel, y.coverage));
  }
  ASSERT_EQ(a.texels.moved.size(), b.texels.moved.size());
  for (size_t i = 0; i < a.texels.moved.size(); ++i) {
    const MovedTexelRecord &x = a.texels.moved[i], &y = b.texels.moved[i];
    EXPECT_EQ(std::tie(x.texel, x.position), std::tie(y.texel, y.position));
  }
  EXPECT_EQ(a.probes.origin, b.probes.origin);
  EXPECT_EQ(a.probes.spacing, b.probes.spacing);
  EXPECT_EQ(a.probes.counts, b.probes.counts);
  ASSERT_EQ(a.probes.probes.size(), b.probes.probes.size());
  for (size_t i = 0; i < a.probes.probes.size(); ++i) {
    EXPECT_EQ(a.probes.probes[i].position, b.probes.probes[i].position);
    EXPECT_EQ(a.probes.probes[i].state, b.probes.probes[i].state);
  }
  expect_same_bytes(a.bvh.nodes, b.bvh.nodes, "bvh nodes");
  EXPECT_EQ(a.bvh.leaf_triangles, b.bvh.leaf_triangles);
  EXPECT_EQ(a.bvh.stack_entries, b.bvh.stack_entries);
  EXPECT_EQ(a.bvh.depth, b.bvh.depth);
}

TEST(SceneFile, RoundTripIsBitwiseExact) {
  SceneFile s = sample();
  s.triangles.uv0[1] = {-0.0f, std::numeric_limits<float>::denorm_min()};
  s.triangles.positions[0][0] = -1.0f;
  const std::vector<uint8_t> bytes = encode_scene(s);
  const SceneFile back = read(bytes);
  expect_bitwise_equal(s, back);
  EXPECT_TRUE(std::signbit(back.triangles.uv0[1][0]));
  EXPECT_EQ(encode_scene(back), bytes);

  const std::string path = fresh_directory("scene-round-trip") + "/scene.bin";
  write_scene_file(path, s);
  EXPECT_EQ(std::filesystem::file_size(path), bytes.size());
  expect_bitwise_equal(s, read_scene_file(path));
}

// Version 2's sections in the textured sample, located from the end of the file: vertex colours
// (12 corners), texture 0 (3 x 2, no alpha), texture 1 (2 x 2 with alpha), the 4 x 2 environment.
struct TexturedOffsets {
  size_t vertex_color, vertex_alpha, texture0, texture1, environment;
};
TexturedOffsets textured_offsets(size_t size) {
  TexturedOffsets o{};
  o.environment = size - (20 + 4 * 2 * 12);
  o.texture1 = o.environment - (20 + 2 * 2 * 16);
  o.texture0 = o.texture1 - (20 + 3 * 2 * 12);
  o.vertex_alpha = o.texture0 - 12 * 4;
  o.vertex_color = o.vertex_alpha - 12 * 12;
  return o;
}

// Textures (with alpha, wrap modes, -0 and a denormal), bindings with transforms, MASK and BLEND,
// vertex colours and the environment sky: bit for bit, and re-encoded to the same bytes.
TEST(SceneFile, TexturedSceneRoundTripsBitwiseExact) {
  const std::vector<uint8_t>& bytes = textured_bytes();
  const SceneFile back = read(bytes);
  expect_bitwise_equal(textured(), back);
  EXPECT_TRUE(std::signbit(back.textures[0].rgb[0]));
  EXPECT_EQ(encode_scene(back), bytes);
  // The documented layout of what version 2 adds.
  auto u32 = [&](size_t offset) { return test::get_u32(bytes, offset); };
  auto f32 = [&](size_t offset) { return std::bit_cast<float>(u32(offset)); };
  EXPECT_EQ(u32(8), 4u);
  EXPECT_EQ(u32(88), 1u);   // environment stored
  EXPECT_EQ(u32(132), 2u);  // texture count
  EXPECT_EQ(u32(136), 1u);  // vertex colours
  EXPECT_EQ(u32(140), 0u);
  const size_t m = sample_offsets().materials + 9;  // material 0 after its name "White"
  EXPECT_EQ(u32(m + 32), 1u);                       // base colour texture 1
  EXPECT_EQ(u32(m + 36), 0xFFFFFFFFu);              // no emissive texture
  EXPECT_EQ(u32(m + 40), 1u);                       // TEXCOORD_1
  EXPECT_EQ(f32(m + 48), -0.5f);                    // offset[1]
  EXPECT_EQ(f32(m + 52), 0.125f);                   // rotation
  EXPECT_EQ(f32(m + 56), 2.0f);                     // scale[0]
  EXPECT_EQ(u32(m + 88), 1u);                       // MASK
  EXPECT_EQ(f32(m + 92), 0.3f);                     // cutoff
  EXPECT_EQ(f32(m + 96), 0.875f);                   // base alpha
  const TexturedOffsets o = textured_offsets(bytes.size());
  EXPECT_EQ(f32(o.vertex_color + 12 + 4), 1.0f);  // corner 1 green
  EXPECT_EQ(f32(o.vertex_alpha), 0.5f);
  EXPECT_EQ(u32(o.texture0), 3u);
  EXPECT_EQ(u32(o.texture0 + 8), 1u);  // clamp
  EXPECT_EQ(u32(o.texture0 + 12), 2u);  // mirrored repeat
  EXPECT_EQ(u32(o.texture0 + 16), 0u);  // no alpha
  EXPECT_EQ(u32(o.texture1 + 16), 1u);
  EXPECT_EQ(f32(o.texture1 + 20 + 48 + 4), 0.25f);
  EXPECT_EQ(u32(o.environment), 4u);
  EXPECT_EQ(f32(bytes.size() - 4), 0.125f);
}

TEST(SceneFile, EveryTruncationAndByteCorruptionOfTheVersion2SectionsIsRefused) {
  const std::vector<uint8_t>& original = textured_bytes();
  const size_t first = textured_offsets(original.size()).vertex_color;
  for (size_t length = 0; length < original.size(); ++length)
    EXPECT_THROW(read_scene(original.data(), length, "scene.bin"), FormatError) << "length " << length;
  for (size_t position = first; position < original.size(); ++position) {
    std::vector<uint8_t> bytes = original;
    bytes[position] ^= 0x10;
    EXPECT_THROW(read(bytes), FormatError) << "byte " << position;
  }
}

// Version 3: the normal texture binding and scale after each material's version 2 fields, the
// tangent frames after the environment, flagged at header offset 140; bit for bit both ways.
TEST(SceneFile, NormalMappedSceneRoundTripsBitwiseExact) {
  const SceneFile mapped = test::make_normal_mapped_sample_scene_file();
  const std::vector<uint8_t> bytes = encode_scene(mapped);
  const SceneFile back = read(bytes);
  expect_bitwise_equal(mapped, back);
  EXPECT_EQ(encode_scene(back), bytes);
  auto u32 = [&](size_t offset) { return test::get_u32(bytes, offset); };
  auto f32 = [&](size_t offset) { return std::bit_cast<float>(u32(offset)); };
  EXPECT_EQ(u32(8), 4u);
  EXPECT_EQ(u32(140), 1u);  // tangents stored
  const size_t m = sample_offsets().materials + 9;  // material 0 after its name "White"
  EXPECT_EQ(u32(m + 100), 0u);      // normal texture 0
  EXPECT_EQ(u32(m + 104), 1u);      // TEXCOORD_1
  EXPECT_EQ(f32(m + 108), 0.5f);    // offset[0]
  EXPECT_EQ(f32(m + 116), 0.375f);  // rotation
  EXPECT_EQ(f32(m + 124), 2.0f);    // scale[1]
  EXPECT_EQ(f32(m + 128), 0.625f);  // normal scale
  // The last section: 12 tangents (f32[3]) then their 12 signs.
  const size_t corners = 3 * mapped.triangles.count(), tangents = bytes.size() - 16 * corners;
  EXPECT_EQ(f32(tangents + 12 * 1), 1.0f);         // corner 1: (1, 0, 0)
  EXPECT_EQ(f32(tangents + 12 * 2 + 8), 0.8f);     // corner 2: (0, 0.6, 0.8)
  EXPECT_EQ(f32(tangents + 12 * corners + 4), -1.0f);  // corner 1's sign
  // The textured sample has no normal map: version 3 without the tangent section.
  EXPECT_EQ(test::get_u32(textured_bytes(), 140), 0u);
  // Every truncation and every byte corruption of the tangent section is refused.
  for (size_t length = tangents; length < bytes.size(); ++length)
    EXPECT_THROW(read_scene(bytes.data(), length, "scene.bin"), FormatError) << "length " << length;
  for (size_t position = tangents; position < bytes.size(); ++position) {
    std::vector<uint8_t> corrupt = bytes;
    corrupt[position] ^= 0x10;
    EXPECT_THROW(read(corrupt), FormatError) << "byte " << position;
  }
  // Field checks, through the reader (checksums refreshed) and the writer alike.
  struct Case {
    void (*edit)(SceneFile&);
    const char* expected;
  };
  const Case cases[] = {
      {[](SceneFile& s) { s.tangents[4][1] = NAN; }, "triangle 1: tangent is not finite"},
      {[](SceneFile& s) { s.tangent_signs[7] = 0.5f; }, "triangle 2: tangent sign is not +1 or -1"},
      {[](SceneFile& s) { s.tangent_signs.pop_back(); }, "tangents: 12 tangents and 11 signs for 12 corners"},
      {[](SceneFile& s) { s.materials[1].normal_texture.texture = 2; },
       "material 1: normal texture: texture 2 does not exist (2 textures)"},
      {[](SceneFile& s) { s.materials[1].normal_texture.tex_coord = 2; }, "material 1: normal texture: tex_coord 2"},
      {[](SceneFile& s) { s.materials[1].normal_scale = INFINITY; }, "material 1: normal scale is not finite"},
  };
  for (const Case& c : cases) {
    SceneFile bad = mapped;
    c.edit(bad);
    expect_format_error([&] { encode_scene(bad); }, c.expected);
  }
  std::vector<uint8_t> bad_sign = bytes;
  put_f32(bad_sign, tangents + 12 * corners + 8, 2.0f);
  refresh_checksums(bad_sign, kHeader);
  expect_format_error([&] { read(bad_sign); }, "scene.bin: triangle 0: tangent sign is not +1 or -1");
}

// Version 4: a triangle may sit in several leaf slots (the builder's spatial splits). Here the leaf
// that ends at the last slot holds its first triangle twice: a valid tree that only version 4 stores.
SceneFile with_a_split_reference() {
  SceneFile s = sample();
  for (BvhNodeRecord& n : s.bvh.nodes)
    for (uint32_t& word : n.child) {
      if (word == kSceneBvhEmptyChild || !(word & kSceneBvhLeafBit)) continue;
      const uint32_t first = (word & ~kSceneBvhLeafBit) >> 2, count = (word & 3u) + 1;
      if (first + count != s.bvh.leaf_triangles.size() || count == 4) continue;
      s.bvh.leaf_triangles.push_back(s.bvh.leaf_triangles[first]);
      ++word;
      return s;
    }
  ADD_FAILURE() << "the sample has no leaf to extend";
  return s;
}

TEST(SceneFile, Version4StoresSplitReferencesAndOlderVersionsRefuseThem) {
  const SceneFile split = with_a_split_reference();
  const std::vector<uint8_t> bytes = encode_scene(split);
  EXPECT_EQ(test::get_u32(bytes, 8), 4u);
  EXPECT_EQ(test::get_u32(bytes, 64), 5u);  // leaf slots for the 4 triangles
  const SceneFile back = read(bytes);
  EXPECT_EQ(back.bvh.leaf_triangles, split.bvh.leaf_triangles);
  EXPECT_EQ(encode_scene(back), bytes);
  expect_format_error([&] { encode_scene(split, 3); },
                      "bvh: 5 leaf slots for 4 triangles: a triangle in several leaf slots is not stored by scene.bin version 3");
  std::vector<uint8_t> labelled_3 = bytes;
  put_u32(labelled_3, 8, 3);
  refresh_checksums(labelled_3, kHeader);
  expect_format_error([&] { read(labelled_3); }, "is not stored by scene.bin version 3");
  // Without split references version 3 is still written, and read.
  const std::vector<uint8_t> v3 = encode_scene(sample(), 3);
  EXPECT_EQ(test::get_u32(v3, 8), 3u);
  expect_bitwise_equal(sample(), read(v3));
}

// Version 2 files (no normal textures, no tangents) are still read, and the version 2 writer
// refuses what only version 3 holds.
TEST(SceneFile, Version2FilesAreStillRead) {
  const std::vector<uint8_t> bytes = encode_scene(textured(), 2);
  EXPECT_EQ(test::get_u32(bytes, 8), 2u);
  EXPECT_EQ(textured_bytes().size() - bytes.size(), 32 * textured().materials.size());
  const SceneFile back = read(bytes);
  expect_bitwise_equal(textured(), back);
  EXPECT_EQ(encode_scene(back, 2), bytes);
  EXPECT_EQ(encode_scene(back), textured_bytes());  // upgraded on rewrite
  std::vector<uint8_t> tangents_v2 = bytes;
  put_u32(tangents_v2, 140, 1);
  refresh_checksums(tangents_v2, kHeader);
  expect_format_error([&] { read(tangents_v2); }, "header: reserved field at offset 140 is 1, not 0");
  const SceneFile mapped = test::make_normal_mapped_sample_scene_file();
  expect_format_error([&] { encode_scene(mapped, 2); }, "tangents: is not stored by scene.bin version 2");
  SceneFile normal_only = textured();
  normal_only.materials[1].normal_texture.texture = 0;
  expect_format_error([&] { encode_scene(normal_only, 2); },
                      "material 1: normal textures are not stored by scene.bin version 2");
}

// Version 1 files (no textures, bindings, alpha modes, vertex colours or environment) are still
// read; the version 1 writer refuses what only version 2 holds.
TEST(SceneFile, Version1FilesAreStillRead) {
  const std::vector<uint8_t> bytes = encode_scene(sample(), 1);
  EXPECT_EQ(test::get_u32(bytes, 8), 1u);
  // Version 1's material record ends after the two texture indices: 92 bytes less per material
  // (60 of version 2's bindings and alpha fields, 32 of version 3's normal texture).
  EXPECT_EQ(sample_bytes().size() - bytes.size(), 92 * sample().materials.size());
  const SceneFile back = read(bytes);
  expect_bitwise_equal(sample(), back);
  EXPECT_EQ(encode_scene(back, 1), bytes);
  EXPECT_EQ(encode_scene(back), sample_bytes());  // upgraded on rewrite

  std::vector<uint8_t> textured_v1 = bytes;
  put_u32(textured_v1, sample_offsets().materials + 9 + 32, 0);
  refresh_checksums(textured_v1, kHeader);
  expect_format_error([&] { read(textured_v1); }, "scene.bin: material 0: texture indices must be -1 in version 1");
  std::vector<uint8_t> environment_v1 = bytes;
  put_u32(environment_v1, 88, 1);
  refresh_checksums(environment_v1, kHeader);
  expect_format_error([&] { read(environment_v1); }, "environment maps are not stored by version 1");
  std::vector<uint8_t> colours_v1 = bytes;
  put_u32(colours_v1, 136, 1);
  refresh_checksums(colours_v1, kHeader);
  expect_format_error([&] { read(colours_v1); }, "header: reserved field at offset 136 is 1, not 0");

  expect_format_error([&] { encode_scene(textured(), 1); }, "textures: is not stored by scene.bin version 1");
  SceneFile masked = sample();
  masked.materials[2].alpha_mode = AlphaMode::Mask;
  expect_format_error([&] { encode_scene(masked, 1); },
                      "material 2: textures and alpha modes are not stored by scene.bin version 1");
  expect_format_error([&] { encode_scene(sample(), 5); }, "format version 5 is not one this writer writes");
}

TEST(SceneFile, SceneWithoutProbesOrTrianglesRoundTrips) {
  SceneFile s;
  s.materials.push_back({});
  s.bvh.nodes.resize(1);
  test::set_empty_children(s.bvh.nodes[0]);
  const SceneFile back = read(encode_scene(s));
  expect_bitwise_equal(s, back);
  EXPECT_TRUE(back.probes.probes.empty());
  EXPECT_EQ(back.bvh.stack_entries, 1u);
}

TEST(SceneFile, HeaderAndPayloadHaveTheDocumentedLayout) {
  const SceneFile& s = sample();
  const std::vector<uint8_t>& b = sample_bytes();
  const Offsets& o = sample_offsets();
  auto f32 = [&](size_t offset) { return std::bit_cast<float>(test::get_u32(b, offset)); };
  auto u32 = [&](size_t offset) { return test::get_u32(b, offset); };
  EXPECT_EQ(std::memcmp(b.data(), "EXSCENE\0", 8), 0);
  EXPECT_EQ(u32(8), 4u);
  EXPECT_EQ(u32(12), 160u);
  const uint32_t counts[15] = {4, 3, 2, 5, 2, 3, 2, 5, 3, 1, 4, 2, 4, 4, 2};
  for (int i = 0; i < 15; ++i) EXPECT_EQ(u32(16 + 4 * size_t(i)), counts[i]) << "header field at " << 16 + 4 * i;
  EXPECT_EQ(f32(76), 0.1f);  // sky
  EXPECT_EQ(f32(84), 0.4f);
  EXPECT_EQ(u32(88), 0u);     // no environment
  EXPECT_EQ(f32(92), 3.5f);   // texel density
  EXPECT_EQ(f32(96), -1.0f);  // probe origin
  EXPECT_EQ(f32(108), 2.0f);  // probe spacing
  EXPECT_EQ(u32(120), 2u);    // probe counts
  EXPECT_EQ(u32(124), 1u);
  EXPECT_EQ(u32(128), 2u);
  EXPECT_EQ(u32(132) | u32(136) | u32(140), 0u);  // no textures, no vertex colours, no tangents
  EXPECT_EQ(test::get_u64(b, 144), b.size() - kHeader);
  EXPECT_EQ(u32(152), crc32(b.data() + kHeader, b.size() - kHeader));
  EXPECT_EQ(u32(156), crc32(b.data(), 156));

  EXPECT_EQ(f32(o.positions + 36 * 2 + 8), -2.0f);    // triangle 2, corner 0, z
  EXPECT_EQ(f32(o.normals + 36 * 3 + 12 + 8), 0.8f);  // triangle 3, corner 1, z
  EXPECT_EQ(f32(o.lightmap_uv + 24 * 1 + 8 + 4), s.triangles.lightmap_uv[4][1]);
  EXPECT_EQ(f32(o.uv0 + 8 * 7), s.triangles.uv0[7][0]);
  EXPECT_EQ(u32(o.material + 4 * 3), 2u);
  EXPECT_EQ(u32(o.instance + 4 * 2), 1u);
  EXPECT_EQ(f32(bvh_plane(o, 1, 2, 2)), s.bvh.nodes[1].lo_y[2]);
  EXPECT_EQ(u32(bvh_child(o, 0, 1)), test::leaf_word(2, 2));
  EXPECT_EQ(u32(bvh_child(o, 0, 3)), kSceneBvhEmptyChild);
  EXPECT_EQ(u32(o.bvh_leaves), 1u);
  EXPECT_EQ(u32(o.pages + 12), 4u);      // page 1 width
  EXPECT_EQ(u32(o.pages + 12 + 8), 2u);  // page 1 live texels
  EXPECT_EQ(u32(o.texel_triangle + 4 * 4), 3u);
  EXPECT_EQ(u32(o.texel_xy + 4 * 2), 3u | (2u << 16));
  EXPECT_EQ(f32(o.texel_barycentrics + 8 * 4 + 4), 0.25f);
  EXPECT_EQ(f32(o.texel_size + 4 * 2), 0.5f);
  EXPECT_EQ(u32(o.partial_coverage + 8 * 1), 2u);
  EXPECT_EQ(f32(o.partial_coverage + 8 * 1 + 4), 1e-3f);
  EXPECT_EQ(u32(o.moved), 3u);
  EXPECT_EQ(f32(o.moved + 4 + 8), -1.999f);
  EXPECT_EQ(f32(o.probes + 16 * 3), 2.0f);
  EXPECT_EQ(u32(o.probes + 16 * 3 + 12), 3u);
  // Material 0: name length 5, "White", base colour, metallic, emission, double_sided, textures.
  EXPECT_EQ(u32(o.materials), 5u);
  EXPECT_EQ(std::memcmp(b.data() + o.materials + 4, "White", 5), 0);
  EXPECT_EQ(f32(o.materials + 9), 0.8f);
  EXPECT_EQ(u32(o.materials + 9 + 12 + 4 + 12 + 4), 0xFFFFFFFFu);  // base colour texture -1
  // The file ends with light 2 ("Sun"): ..., intensity, cos_inner 1, cos_outer 0.
  EXPECT_EQ(f32(b.size() - 8), 1.0f);
  EXPECT_EQ(f32(b.size() - 12), 2.5f);
}

TEST(SceneFile, EveryTruncationIsRefused) {
  const std::vector<uint8_t>& bytes = sample_bytes();
  for (size_t length = 0; length < bytes.size(); ++length)
    EXPECT_THROW(read_scene(bytes.data(), length, "scene.bin"), FormatError) << "length " << length;
}

TEST(SceneFile, TrailingBytesAreRefused) {
  std::vector<uint8_t> bytes = sample_bytes();
  bytes.push_back(0);
  expect_format_error([&] { read(bytes); }, "unexpected bytes after the payload");
}

TEST(SceneFile, EverySingleByteCorruptionIsRefused) {
  const std::vector<uint8_t>& original = sample_bytes();
  for (size_t position = 0; position < original.size(); ++position)
    for (uint8_t flip : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
      std::vector<uint8_t> bytes = original;
      bytes[position] ^= flip;
      EXPECT_THROW(read(bytes), FormatError) << "byte " << position << " xor " << int(flip);
    }
}

TEST(SceneFile, OtherVersionsAreRefusedByName) {
  std::vector<uint8_t> bytes = sample_bytes();
  put_u32(bytes, 8, 5);
  refresh_checksums(bytes, kHeader);
  try {
    read(bytes);
    FAIL() << "version 5 accepted";
  } catch (const FormatError& e) {
    EXPECT_STREQ(e.what(), "scene.bin: format version 5 is newer than this loader (4)");
  }
  put_u32(bytes, 8, 0);
  refresh_checksums(bytes, kHeader);
  expect_format_error([&] { read(bytes); }, "scene.bin: format version 0 is older than this loader supports (1)");
}

TEST(SceneFile, WrongMagicIsRefused) {
  std::vector<uint8_t> bytes = sample_bytes();
  bytes[1] = 'Y';
  expect_format_error([&] { read(bytes); }, "wrong magic");
}

// Each case edits a valid file, recomputes the checksums, and names what the message must say.
struct StructuralCase {
  const char* name;
  void (*edit)(std::vector<uint8_t>&, const Offsets&);
  const char* expected;
};

const StructuralCase kStructuralCases[] = {
    {"bvh child out of range", [](auto& b, auto& o) { put_u32(b, bvh_child(o, 0, 0), 2); },
     "bvh node 0: child 0 index 2 is out of range (2 nodes)"},
    {"bvh child before its parent", [](auto& b, auto& o) { put_u32(b, bvh_child(o, 1, 0), 0); },
     "bvh node 1: child 0 index 0 is not after its parent"},
    {"bvh self cycle", [](auto& b, auto& o) { put_u32(b, bvh_child(o, 1, 0), 1); },
     "bvh node 1: child 0 index 1 is not after its parent"},
    {"bvh node listed twice", [](auto& b, auto& o) { put_u32(b, bvh_child(o, 0, 1), 1); },
     "child node 1 has more than one parent"},
    {"bvh leaf range out of range", [](auto& b, auto& o) { put_u32(b, bvh_child(o, 0, 1), test::leaf_word(3, 2)); },
     "bvh node 0: child 1 leaf slots 3 + 2 run past the 4 leaf slots"},
    {"bvh leaf slots shared", [](auto& b, auto& o) { put_u32(b, bvh_child(o, 1, 2), test::leaf_word(0, 1)); },
     "leaf slot 0 is in more than one leaf"},
    {"bvh leaf slot in no leaf", [](auto& b, auto& o) { put_u32(b, bvh_child(o, 0, 1), test::leaf_word(2, 1)); },
     "bvh: leaf slot 3 is in no leaf"},
    {"bvh triangle missing", [](auto& b, auto& o) { put_u32(b, o.bvh_leaves + 4, 2); }, "is in no leaf slot"},
    {"bvh leaf triangle out of range", [](auto& b, auto& o) { put_u32(b, o.bvh_leaves, 4); },
     "bvh: leaf slot 0: triangle 4 does not exist"},
    {"bvh box misses its triangle", [](auto& b, auto& o) { put_f32(b, bvh_plane(o, 0, 3, 1), 1.5f); },
     "do not contain its corner"},
    {"bvh box misses its child's box", [](auto& b, auto& o) { put_f32(b, bvh_plane(o, 0, 1, 0), 0.5f); },
     "bvh node 0: child 0 box does not contain node 1's child"},
    {"bvh nan bound", [](auto& b, auto& o) { put_f32(b, bvh_plane(o, 1, 4, 3), std::nanf("")); },
     "bvh node 1: child 3 bounds are not finite"},
    {"bvh stack bound", [](auto& b, auto&) { put_u32(b, 68, 3); }, "bvh: stack bound 3 is not the 4 the tree needs"},
    {"bvh depth", [](auto& b, auto&) { put_u32(b, 72, 9); }, "bvh: depth 9 is not the tree's 2"},
    {"texel triangle out of range", [](auto& b, auto& o) { put_u32(b, o.texel_triangle + 4, 4); },
     "texel 1: triangle 4 does not exist (4 triangles)"},
    {"texel on another page's triangle", [](auto& b, auto& o) { put_u32(b, o.texel_triangle + 4, 2); },
     "texel 1: its triangle 2 belongs to instance 1 on page 1, not page 0"},
    {"texel outside its page", [](auto& b, auto& o) { put_u32(b, o.texel_xy + 4 * 3, 3u << 16 | 4u); },
     "texel 3: (4, 3) lies outside page 1 (4 x 4)"},
    {"texels out of Morton order", [](auto& b, auto& o) { put_u32(b, o.texel_xy + 4, 0); },
     "texel 1: (0, 0) is not after the previous texel of page 0 in Morton order"},
    {"barycentrics off the triangle", [](auto& b, auto& o) { put_f32(b, o.texel_barycentrics + 8, 0.5f); },
     "texel 1: barycentrics 0.500000, 1.000000 are not on the triangle"},
    {"nan barycentric", [](auto& b, auto& o) { put_f32(b, o.texel_barycentrics, std::nanf("")); },
     "texel 0: barycentrics nan"},
    {"zero coverage", [](auto& b, auto& o) { put_f32(b, o.partial_coverage + 4, 0.0f); },
     "partial coverage 0: coverage 0.000000 is not in (0, 1)"},
    {"full coverage listed", [](auto& b, auto& o) { put_f32(b, o.partial_coverage + 8 + 4, 1.0f); },
     "partial coverage 1: coverage 1.000000 is not in (0, 1)"},
    {"partial coverage out of order", [](auto& b, auto& o) { put_u32(b, o.partial_coverage + 8, 1); },
     "partial coverage 1: texel 1 is out of range or not after the previous one"},
    {"partial coverage out of range", [](auto& b, auto& o) { put_u32(b, o.partial_coverage + 16, 5); },
     "partial coverage 2: texel 5 is out of range"},
    {"negative world texel size", [](auto& b, auto& o) { put_f32(b, o.texel_size + 4, -0.3f); },
     "triangle 1: world texel size -0.300000 is not a finite non-negative number"},
    {"moved position", [](auto& b, auto& o) { put_f32(b, o.moved + 8, INFINITY); },
     "moved texel 0: position is not finite"},
    {"moved texel out of range", [](auto& b, auto& o) { put_u32(b, o.moved, 5); },
     "moved texel 0: texel 5 is out of range"},
    {"nan position", [](auto& b, auto& o) { put_f32(b, o.positions + 36 * 3 + 16, std::nanf("")); },
     "triangle 3: position is not finite"},
    {"inf normal", [](auto& b, auto& o) { put_f32(b, o.normals + 4, INFINITY); }, "triangle 0: normal is not finite"},
    {"triangle material out of range", [](auto& b, auto& o) { put_u32(b, o.material + 8, 3); },
     "triangle 2: material 3 does not exist (3 materials)"},
    {"triangle in another instance", [](auto& b, auto& o) { put_u32(b, o.instance + 4, 1); },
     "triangle 1: lies outside the triangle range of its instance 1"},
    {"page too wide", [](auto& b, auto& o) { put_u32(b, o.pages, 65536); },
     "page 0: size 65536 x 4 is not within 1 .. 65535"},
    {"page live count", [](auto& b, auto& o) { put_u32(b, o.pages + 8, 2); }, "pages list 4 live texels, there are 5"},
    {"probe state", [](auto& b, auto& o) { put_u32(b, o.probes + 12, 4); },
     "probe 0: state 4 is not a known ProbeState"},
    {"probe position", [](auto& b, auto& o) { put_f32(b, o.probes + 16 + 4, -INFINITY); },
     "probe 1: position is not finite"},
    {"probe counts", [](auto& b, auto&) { put_u32(b, 120, 3); }, "probe count 4 is not 3 x 1 x 2"},
    {"probe spacing", [](auto& b, auto&) { put_f32(b, 112, 0.0f); }, "probe spacing on axis 1 is not a positive"},
    {"sky environment flag", [](auto& b, auto&) { put_u32(b, 88, 2); }, "header: sky environment 2 is not 0 or 1"},
    {"sky environment missing", [](auto& b, auto&) { put_u32(b, 88, 1); },
     "scene.bin: sky environment: record runs past the end of the payload"},
    {"vertex colours flag", [](auto& b, auto&) { put_u32(b, 136, 2); }, "header: vertex_colors 2 is not 0 or 1"},
    {"vertex colours missing", [](auto& b, auto&) { put_u32(b, 136, 1); }, "the header's counts need at least"},
    {"textures missing", [](auto& b, auto&) { put_u32(b, 132, 1); },
     "scene.bin: texture 0: record runs past the end of the payload"},
    {"huge texture count", [](auto& b, auto&) { put_u32(b, 132, 0xFFFFFFFFu); }, "the header's counts need at least"},
    {"negative sky", [](auto& b, auto&) { put_f32(b, 80, -0.5f); }, "sky radiance must be finite and >= 0"},
    {"texel density", [](auto& b, auto&) { put_f32(b, 92, std::nanf("")); }, "texel density nan"},
    {"tangents flag", [](auto& b, auto&) { put_u32(b, 140, 2); }, "header: tangents 2 is not 0 or 1"},
    {"tangents missing", [](auto& b, auto&) { put_u32(b, 140, 1); }, "the header's counts need at least"},
    {"too many triangles", [](auto& b, auto&) { put_u32(b, 16, 1u << 29); }, "triangles exceed the limit"},
    {"counts beyond the payload", [](auto& b, auto&) { put_u32(b, 44, 0x40000000u); },
     "the header's counts need at least"},
    {"material texture", [](auto& b, auto& o) { put_u32(b, o.materials + 9 + 32, 0); },
     "material 0: base colour texture: texture 0 does not exist (0 textures)"},
    {"material tex_coord", [](auto& b, auto& o) { put_u32(b, o.materials + 9 + 40, 2); },
     "material 0: base colour texture: tex_coord 2 is not 0 or 1"},
    {"material texture transform", [](auto& b, auto& o) { put_f32(b, o.materials + 9 + 52, INFINITY); },
     "material 0: base colour texture: texture transform is not finite"},
    {"material alpha mode", [](auto& b, auto& o) { put_u32(b, o.materials + 9 + 88, 3); },
     "material 0: alpha mode 3 is not OPAQUE (0), MASK (1) or BLEND (2)"},
    {"material alpha cutoff", [](auto& b, auto& o) { put_f32(b, o.materials + 9 + 92, -1.0f); },
     "material 0: alpha cutoff must be finite and >= 0"},
    {"material base alpha", [](auto& b, auto& o) { put_f32(b, o.materials + 9 + 96, 1.5f); },
     "material 0: base alpha must be in [0, 1]"},
    {"material metallic", [](auto& b, auto& o) { put_f32(b, o.materials + 9 + 12, 1.5f); },
     "material 0: metallic must be in [0, 1]"},
    {"material double_sided", [](auto& b, auto& o) { put_u32(b, o.materials + 9 + 28, 2); },
     "material 0: double_sided is 2, not 0 or 1"},
    {"name past the payload", [](auto& b, auto& o) { put_u32(b, o.materials, 60000); },
     "material 0: name runs past the end of the payload"},
    {"huge name length", [](auto& b, auto& o) { put_u32(b, o.materials, 0xFFFFFFFFu); },
     "material 0: name length 4294967295 exceeds 65535"},
};

TEST(SceneFile, StructurallyWrongFilesWithRightChecksumsAreRefused) {
  for (const StructuralCase& c : kStructuralCases) {
    SCOPED_TRACE(c.name);
    std::vector<uint8_t> bytes = sample_bytes();
    c.edit(bytes, sample_offsets());
    refresh_checksums(bytes, kHeader);
    expect_format_error([&] { read(bytes); }, c.expected);
  }
}

struct TexturedCase {
  const char* name;
  void (*edit)(std::vector<uint8_t>&, const TexturedOffsets&);
  const char* expected;
};

const TexturedCase kTexturedCases[] = {
    {"texture too wide", [](auto& b, auto& o) { put_u32(b, o.texture0, 65536); },
     "scene.bin: texture 0: size 65536 x 2 is not within 1 .. 65535"},
    {"texture pixels beyond the payload",
     [](auto& b, auto& o) {
       put_u32(b, o.texture0, 65535), put_u32(b, o.texture0 + 4, 65535);
     },
     "scene.bin: texture 0: 65535 x 65535 texels need 51538034700 bytes, the payload has"},
    {"texture has_alpha", [](auto& b, auto& o) { put_u32(b, o.texture1 + 16, 2); },
     "scene.bin: texture 1: has_alpha is 2, not 0 or 1"},
    {"texture wrap", [](auto& b, auto& o) { put_u32(b, o.texture0 + 8, 3); }, "scene.bin: texture 0: wrap modes 3, 2"},
    {"texture colour nan", [](auto& b, auto& o) { put_f32(b, o.texture0 + 20 + 12, NAN); },
     "scene.bin: texture 0: texel 1: colour is not finite"},
    {"texture alpha", [](auto& b, auto& o) { put_f32(b, o.texture1 + 20 + 48 + 4, 2.0f); },
     "scene.bin: texture 1: texel 1: alpha is not in [0, 1]"},
    {"environment wrap", [](auto& b, auto& o) { put_u32(b, o.environment + 12, 7); },
     "scene.bin: sky environment: wrap modes 0, 7 are not"},
    {"environment infinite", [](auto& b, auto& o) { put_f32(b, o.environment + 20 + 4 * 23, INFINITY); },
     "scene.bin: sky environment: texel 7: colour is not finite"},
    {"environment zero height", [](auto& b, auto& o) { put_u32(b, o.environment + 4, 0); },
     "scene.bin: sky environment: size 4 x 0 is not within 1 .. 65535"},
    {"vertex colour nan", [](auto& b, auto& o) { put_f32(b, o.vertex_color + 12 * 4 + 8, NAN); },
     "scene.bin: triangle 1: vertex colour is not finite"},
    {"vertex alpha infinite", [](auto& b, auto& o) { put_f32(b, o.vertex_alpha + 4 * 11, -INFINITY); },
     "scene.bin: triangle 3: vertex colour is not finite"},
    {"material texture out of range", [](auto& b, auto&) { put_u32(b, sample_offsets().materials + 9 + 32, 2); },
     "scene.bin: material 0: base colour texture: texture 2 does not exist (2 textures)"},
    {"version 1 with textures", [](auto& b, auto&) { put_u32(b, 8, 1); },
     "scene.bin: header: reserved field at offset 132 is 2, not 0"},
};

TEST(SceneFile, StructurallyWrongVersion2SectionsAreRefused) {
  for (const TexturedCase& c : kTexturedCases) {
    SCOPED_TRACE(c.name);
    std::vector<uint8_t> bytes = textured_bytes();
    c.edit(bytes, textured_offsets(bytes.size()));
    refresh_checksums(bytes, kHeader);
    expect_format_error([&] { read(bytes); }, c.expected);
  }
}

// Cross references between records, edited in memory: the writer must refuse them as the reader does.
struct RecordCase {
  const char* name;
  void (*edit)(SceneFile&);
  const char* expected;
};

const RecordCase kRecordCases[] = {
    {"node cycle", [](SceneFile& s) { s.nodes[0].parent = 3; },
     "node 0: hierarchy is cyclic or deeper than 256 levels"},
    {"node parent out of range", [](SceneFile& s) { s.nodes[1].parent = 9; }, "node 1: parent 9 is not another node"},
    {"node own parent", [](SceneFile& s) { s.nodes[1].parent = 1; }, "node 1: parent 1 is not another node"},
    {"node outside the scene under one inside", [](SceneFile& s) { s.nodes[4].parent = 0; },
     "node 4: is not in the scene but its parent 0 is"},
    {"node light not placed by it", [](SceneFile& s) { s.nodes[1].light = 0; },
     "node 1: light 0 does not exist or is not placed by it"},
    {"light node without the link", [](SceneFile& s) { s.lights[0].node = 1; },
     "light 0: node 1 does not exist or does not place it"},
    {"camera node out of range", [](SceneFile& s) { s.cameras.push_back(s.cameras[0]), s.cameras[2].node = 5; },
     "camera 2: node 5 does not exist or does not place it"},
    {"camera node does not place it", [](SceneFile& s) { s.cameras.push_back(s.cameras[0]), s.cameras[2].node = 1; },
     "camera 2: node 1 does not exist or does not place it"},
    {"node with matrix and TRS",
     [](SceneFile& s) {
       s.nodes[2].scale = {2, 2, 2};
     },
     "node 2: has a matrix and a translation, rotation or scale"},
    {"node zero quaternion",
     [](SceneFile& s) {
       s.nodes[0].rotation = {0, 0, 0, 0};
     },
     "node 0: rotation quaternion has zero length"},
    {"node nan translation", [](SceneFile& s) { s.nodes[1].translation[2] = NAN; },
     "node 1: local transform is not finite"},
    {"instance mesh not its node's", [](SceneFile& s) { s.instances[1].mesh = 0; },
     "instance 1: mesh 0 is not node 2's mesh 1"},
    {"instance node outside the scene", [](SceneFile& s) { s.instances[0].node = 4, s.instances[0].mesh = 7; },
     "instance 0: node 4 is not in the scene"},
    {"instance rectangle off its page", [](SceneFile& s) { s.instances[0].width = 8; },
     "instance 0: rectangle 1, 1, 8 x 2 does not fit page 0"},
    {"instance world nan", [](SceneFile& s) { s.instances[0].world[5] = NAN; },
     "instance 0: world transform is not finite"},
    {"instance page out of range", [](SceneFile& s) { s.instances[1].page = 2; },
     "instance 1: page 2 does not exist (2 pages)"},
    {"instance range past the triangles", [](SceneFile& s) { s.instances[1].triangle_count = 3; },
     "instance 1: triangles 2 + 3 run past the 4 triangles"},
    {"spot cone", [](SceneFile& s) { s.lights[1].cos_outer = 0.95f; },
     "light 1: spot cos_outer 0.950000 exceeds cos_inner"},
    {"light direction",
     [](SceneFile& s) {
       s.lights[2].direction = {1, 1, 0};
     },
     "light 2: direction is not a unit vector"},
    {"light type", [](SceneFile& s) { s.lights[2].type = LightType(3); }, "light 2: type 3 is not point (0)"},
    {"camera znear", [](SceneFile& s) { s.cameras[0].znear = 0; }, "camera 0: perspective needs yfov > 0"},
    {"camera zfar", [](SceneFile& s) { s.cameras[1].zfar = 0; }, "camera 1: orthographic needs"},
    {"emissive texture", [](SceneFile& s) { s.materials[1].emissive_texture.texture = 2; },
     "material 1: emissive texture: texture 2 does not exist (0 textures)"},
    {"texture pixels", [](SceneFile& s) { s.textures.push_back({2, 1, {}, {}, {1, 2, 3}, {}}); },
     "texture 0: pixel arrays do not hold 2 texels"},
    {"texture nan", [](SceneFile& s) { s.textures.push_back({1, 1, {}, {}, {1, NAN, 3}, {}}); },
     "texture 0: texel 0: colour is not finite"},
    {"texture alpha", [](SceneFile& s) { s.textures.push_back({1, 1, {}, {}, {1, 2, 3}, {1.5f}}); },
     "texture 0: texel 0: alpha is not in [0, 1]"},
    {"texture wrap", [](SceneFile& s) { s.textures.push_back({1, 1, TextureWrap(3), {}, {1, 2, 3}, {}}); },
     "texture 0: wrap modes 3, 0 are not"},
    {"texture size", [](SceneFile& s) { s.textures.push_back({0, 1, {}, {}, {}, {}}); },
     "texture 0: size 0 x 1 is not within 1 .. 65535"},
    {"sky environment size", [](SceneFile& s) { s.sky_environment.rgb = {1, 1, 1}; },
     "sky environment: size 0 x 0 is not within 1 .. 65535"},
    {"vertex colours per corner", [](SceneFile& s) { s.vertex_color.assign(3, {1, 1, 1}), s.vertex_alpha.assign(3, 1); },
     "vertex colours: 3 colours and 3 alphas for 12 corners"},
    {"vertex colour nan",
     [](SceneFile& s) {
       s.vertex_color.assign(12, {1, 1, 1}), s.vertex_alpha.assign(12, 1);
       s.vertex_alpha[7] = NAN;
     },
     "triangle 2: vertex colour is not finite"},
    {"moved texels out of order", [](SceneFile& s) { s.texels.moved.push_back(s.texels.moved[0]); },
     "moved texel 1: texel 3 is out of range or not after the previous moved texel"},
    {"probe grid without counts",
     [](SceneFile& s) {
       s.probes.counts = {0, 0, 0};
     },
     "no probe grid (counts 0) but origin, spacing or probes are set"},
    {"triangle arrays", [](SceneFile& s) { s.triangles.uv0.pop_back(); }, "triangle arrays disagree in length"},
    {"leaf slot count", [](SceneFile& s) { s.bvh.leaf_triangles.resize(9, 0); },
     "bvh: 9 leaf slots for 4 triangles (each triangle is in one to two slots in all)"},
    {"leaf slot in no leaf", [](SceneFile& s) { s.bvh.leaf_triangles.push_back(0); }, "bvh: leaf slot 4 is in no leaf"},
    {"no bvh root", [](SceneFile& s) { s.bvh.nodes.clear(); }, "bvh: no root node"},
};

TEST(SceneFile, WriterRefusesInvalidRecordsAndReaderRefusesTheirBytes) {
  for (const RecordCase& c : kRecordCases) {
    SCOPED_TRACE(c.name);
    SceneFile s = sample();
    c.edit(s);
    expect_format_error([&] { encode_scene(s); }, c.expected);
  }
}

TEST(SceneFile, NodeHierarchyDeeperThanTheLimitIsRefused) {
  SceneFile s = sample();
  const size_t first = s.nodes.size();
  for (size_t i = 0; i < kMaxSceneNodeDepth + 2; ++i) {  // 258 levels
    NodeRecord n;
    n.parent = i == 0 ? -1 : int32_t(first + i - 1);
    s.nodes.push_back(n);
  }
  expect_format_error([&] { encode_scene(s); }, "deeper than 256 levels");
  s.nodes.pop_back();  // 257 levels (depths 0 .. 256), as the importer allows
  EXPECT_NO_THROW(read(encode_scene(s)));
}

TEST(SceneFile, MissingFileIsAnAccessError) {
  EXPECT_THROW(read_scene_file(fresh_directory("scene-missing") + "/nope.bin"), FileAccessError);
}

}  // namespace
}  // namespace exitance::formats
