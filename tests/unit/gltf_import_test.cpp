// Unit tests of the glTF importer's front door: validate_gltf_json (schema, references, sizes,
// overflow-safe bounds) and the NaN-normal repair in import_gltf.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/import/gltf_json_validation.h"
#include "exitance/bake/input_error.h"
#include "exitance/runtime/alpha_coverage.h"
#include "exitance/runtime/material_eval.h"

#include "support/base64.h"

namespace exitance {
namespace {

using json = nlohmann::json;

using test::base64;

void append_floats(std::vector<unsigned char>& bytes, const std::vector<float>& values) {
  const size_t at = bytes.size();
  bytes.resize(at + values.size() * 4);
  std::memcpy(bytes.data() + at, values.data(), values.size() * 4);
}

// One triangle: POSITION (36 bytes), NORMAL (36 bytes), TEXCOORD_1 (24 bytes) in one data-uri buffer.
json triangle_document(const std::vector<float>& normals = {0, 0, 1, 0, 0, 1, 0, 0, 1}) {
  std::vector<unsigned char> data;
  append_floats(data, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  append_floats(data, normals);
  append_floats(data, {0, 0, 1, 0, 0, 1});
  json document = json::parse(R"({
    "asset": {"version": "2.0"},
    "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_1": 2}}]}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
      {"bufferView": 0, "byteOffset": 36, "componentType": 5126, "count": 3, "type": "VEC3"},
      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
    "bufferViews": [{"buffer": 0, "byteLength": 72}, {"buffer": 0, "byteOffset": 72, "byteLength": 24}],
    "buffers": [{"byteLength": 96}]
  })");
  document["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(data);
  return document;
}

// The element named by the InputError validation throws ("" when the document passes).
std::string failing_element(const json& document, std::optional<uint64_t> glb_bin = std::nullopt,
                            const std::string& base_dir = "") {
  try {
    validate_gltf_json(document, "test.gltf", base_dir, glb_bin);
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "test.gltf");
    return e.element();
  }
  return "";
}

TEST(GltfJsonValidation, AcceptsAValidTriangle) { EXPECT_EQ(failing_element(triangle_document()), ""); }

TEST(GltfJsonValidation, WrongTypesNameTheirElement) {
  json d = triangle_document();
  d["accessors"][1]["count"] = "3";
  EXPECT_EQ(failing_element(d), "accessor 1");
  d = triangle_document();
  d["accessors"][0]["bufferView"] = 0.0;  // tinygltf would silently drop a fractional optional index
  EXPECT_EQ(failing_element(d), "accessor 0");
  d = triangle_document();
  d["meshes"][0]["primitives"] = json::object();
  EXPECT_EQ(failing_element(d), "mesh 0");
  d = triangle_document();
  d["scenes"][0]["name"] = 42;
  EXPECT_EQ(failing_element(d), "scene 0");
  d = triangle_document();
  d["scene"] = "hello";
  EXPECT_EQ(failing_element(d), "scene");
  d = triangle_document();
  d["scene"] = 2;
  EXPECT_EQ(failing_element(d), "scene 2");
}

TEST(GltfJsonValidation, AssetVersionAndRequiredExtensions) {
  json d = triangle_document();
  d["asset"]["minVersion"] = "2.1";
  d["asset"]["version"] = "2.1";
  EXPECT_EQ(failing_element(d), "asset");
  d = triangle_document();
  d["asset"].erase("version");
  EXPECT_EQ(failing_element(d), "asset");
  d = triangle_document();
  d["extensionsRequired"] = {"KHR_texture_transform"};  // supported, but not listed as used
  EXPECT_EQ(failing_element(d), "extensionsRequired");
  d["extensionsUsed"] = {"KHR_texture_transform"};
  EXPECT_EQ(failing_element(d), "");
  d["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  EXPECT_EQ(failing_element(d), "extensionsRequired");
}

TEST(GltfJsonValidation, HugeOffsetsAndCountsDoNotWrap) {
  json d = triangle_document();
  d["bufferViews"][1]["byteOffset"] = std::numeric_limits<uint64_t>::max() - 8;
  EXPECT_EQ(failing_element(d), "bufferView 1");
  d = triangle_document();
  d["bufferViews"][1]["byteOffset"] = int64_t(1) << 62;
  EXPECT_EQ(failing_element(d), "bufferView 1");
  d = triangle_document();
  d["accessors"][2]["count"] = int64_t(1) << 61;  // stride * count would overflow 64 bits
  EXPECT_EQ(failing_element(d), "accessor 2");
  d = triangle_document();
  d["bufferViews"][0]["byteStride"] = 252;
  d["accessors"][0]["count"] = std::numeric_limits<int64_t>::max();
  EXPECT_EQ(failing_element(d), "accessor 0");
}

TEST(GltfJsonValidation, AccessorAlignmentAndTypes) {
  json d = triangle_document();
  d["accessors"][1]["byteOffset"] = 34;
  EXPECT_EQ(failing_element(d), "accessor 1");
  d = triangle_document();
  d["accessors"][2]["componentType"] = 5123;  // TEXCOORD as unsigned short must be normalized
  EXPECT_EQ(failing_element(d), "mesh 0 primitive 0");
  d["accessors"][2]["normalized"] = true;
  EXPECT_EQ(failing_element(d), "");
  d = triangle_document();
  d["accessors"][0]["componentType"] = 5130;
  EXPECT_EQ(failing_element(d), "accessor 0");
}

TEST(GltfJsonValidation, BufferSources) {
  json d = triangle_document();
  d["buffers"][0]["byteLength"] = 97;  // the data uri holds 96 bytes
  EXPECT_EQ(failing_element(d), "buffer 0");
  d = triangle_document();
  d["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@not*base64";
  EXPECT_EQ(failing_element(d), "buffer 0");
  for (const char* uri : {".", "/dev/zero", "http://127.0.0.1/x.bin", "missing.bin"}) {
    d = triangle_document();
    d["buffers"][0]["uri"] = uri;
    EXPECT_EQ(failing_element(d, std::nullopt, std::filesystem::temp_directory_path().string()), "buffer 0") << uri;
  }
  d = triangle_document();
  d["buffers"][0].erase("uri");
  EXPECT_EQ(failing_element(d), "buffer 0");           // .gltf: a buffer needs a uri
  EXPECT_EQ(failing_element(d, 96), "");               // .glb: BIN chunk large enough
  EXPECT_EQ(failing_element(d, 40), "buffer 0");       // BIN chunk too short
  EXPECT_EQ(failing_element(d, 0), "buffer 0");        // no BIN chunk at all
}

TEST(GltfJsonValidation, SceneGraphAndPrimitiveRules) {
  json d = triangle_document();
  d["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  d["nodes"][0]["translation"] = {1, 0, 0};
  EXPECT_EQ(failing_element(d), "node 0");
  d = triangle_document();
  d["nodes"][0]["children"] = {7};
  EXPECT_EQ(failing_element(d), "node 0");
  d = triangle_document();
  d["meshes"][0]["primitives"] = json::array();
  EXPECT_EQ(failing_element(d), "mesh 0");
  d = triangle_document();
  d["accessors"][0]["count"] = 2;  // POSITION count differs from the others and is not a multiple of 3
  EXPECT_EQ(failing_element(d), "mesh 0 primitive 0");
  d = triangle_document();
  d["materials"] = json::parse(R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": -1}}}])");
  EXPECT_EQ(failing_element(d), "material 0");
}

TEST(GltfImport, NonFiniteNormalsAreRepairedWithAWarning) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_import_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "nan_normal.gltf").string();
  std::ofstream(path) << triangle_document({nan, 0, 1, inf, 0, 1, 0, 0, 1}).dump();
  Diagnostics diagnostics;
  const Scene scene = import_gltf(path, ImportOptions{}, diagnostics);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(scene.triangle_count(), 1u);
  for (const Vec3& n : scene.normals) {
    EXPECT_TRUE(is_finite(n));
    EXPECT_NEAR(length(n), 1.0f, 1e-5f);
  }
  bool warned = false;
  for (const std::string& w : diagnostics.warnings) warned = warned || w.find("NaN or infinite") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Vertex normals turn with their node: a flat triangle's +Z normals stay its geometric normal under
// a rotation (and a non-uniform scale), rather than turning the other way.
TEST(GltfImport, VertexNormalsTurnWithTheirNode) {
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_import_test_turn_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "turned.gltf").string();
  json d = triangle_document();
  d["nodes"][0]["rotation"] = {0.3, 0.4, -0.2, std::sqrt(1 - 0.09 - 0.16 - 0.04)};
  d["nodes"][0]["scale"] = {1, 3, 0.5};
  std::ofstream(path) << d.dump();
  Diagnostics diagnostics;
  const Scene scene = import_gltf(path, ImportOptions{}, diagnostics);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(scene.triangle_count(), 1u);
  const Vec3 face = triangle_normal(scene, 0);
  // Both unit vectors from float products of the same matrix: a few float roundings apart.
  for (const Vec3& n : scene.normals)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(n[c], face[c], 1e-6f) << "component " << c;
}

TEST(GltfImport, NonFinitePositionIsAnErrorNamingTheAccessor) {
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_import_test_pos_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "nan_position.gltf").string();
  json d = triangle_document();
  std::vector<unsigned char> data;
  append_floats(data, {std::numeric_limits<float>::quiet_NaN(), 0, 0, 1, 0, 0, 0, 1, 0});
  append_floats(data, {0, 0, 1, 0, 0, 1, 0, 0, 1});
  append_floats(data, {0, 0, 1, 0, 0, 1});
  d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(data);
  std::ofstream(path) << d.dump();
  Diagnostics diagnostics;
  try {
    import_gltf(path, ImportOptions{}, diagnostics);
    ADD_FAILURE() << "NaN POSITION was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.element(), "accessor 0");
  }
  std::filesystem::remove_all(dir);
}

// Scene::nodes keeps every glTF node (names, parents, local transforms as written), instances
// their world transform, lights and cameras the node that places them; an invalid camera is
// dropped with a warning.
TEST(GltfImport, KeepsTheNodeHierarchyCamerasAndLightNodes) {
  json d = triangle_document();
  d["extensionsUsed"] = {"KHR_lights_punctual"};
  d["extensions"]["KHR_lights_punctual"]["lights"] =
      json::parse(R"([{"type": "point", "name": "Lamp", "intensity": 2}])");
  d["cameras"] = json::parse(R"([
    {"type": "perspective", "name": "Main", "perspective": {"yfov": 0.7, "znear": 0.1, "zfar": 50, "aspectRatio": 1.5}},
    {"type": "orthographic", "name": "Broken", "orthographic": {"xmag": 0, "ymag": 1, "znear": 0, "zfar": 10}}])");
  d["nodes"] = json::parse(R"([
    {"name": "Root", "translation": [1, 2, 3], "scale": [2, 2, 2], "children": [1, 2, 3], "camera": 0},
    {"name": "Tri", "mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1]},
    {"name": "LampNode", "rotation": [0, 0, 0, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    {"name": "BadCam", "camera": 1},
    {"name": "Elsewhere", "rotation": [0, 0, 0, 0], "mesh": 0}])");
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_import_test_nodes_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "nodes.gltf").string();
  std::ofstream(path) << d.dump();
  Diagnostics diagnostics;
  const Scene scene = import_gltf(path, ImportOptions{}, diagnostics);
  std::filesystem::remove_all(dir);

  ASSERT_EQ(scene.nodes.size(), 5u);
  EXPECT_EQ(scene.nodes[0].name, "Root");
  EXPECT_EQ(scene.nodes[0].parent, -1);
  EXPECT_TRUE(scene.nodes[0].in_scene);
  EXPECT_FALSE(scene.nodes[0].has_matrix);
  EXPECT_EQ(scene.nodes[0].translation, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(scene.nodes[0].scale, (std::array<double, 3>{2, 2, 2}));
  EXPECT_EQ(scene.nodes[0].camera, 0);
  EXPECT_EQ(scene.nodes[1].parent, 0);
  EXPECT_EQ(scene.nodes[1].mesh, 0);
  EXPECT_TRUE(scene.nodes[1].has_matrix);
  EXPECT_EQ(scene.nodes[1].matrix[14], 5.0);
  EXPECT_EQ(scene.nodes[2].rotation, (std::array<double, 4>{0, 0, 0, 2}));  // as written, not normalized
  EXPECT_EQ(scene.nodes[2].light, 0);
  EXPECT_EQ(scene.nodes[3].camera, -1);  // its camera was dropped
  EXPECT_FALSE(scene.nodes[4].in_scene);
  EXPECT_EQ(scene.nodes[4].parent, -1);
  EXPECT_EQ(scene.nodes[4].rotation, (std::array<double, 4>{0, 0, 0, 1}));  // unusable, never drawn: reset

  ASSERT_EQ(scene.instances.size(), 1u);
  EXPECT_EQ(scene.instances[0].node, 1);
  // World = Root (T (1,2,3), S 2) * Tri (T (0,0,5)): translation (1, 2, 13), scale 2.
  const Matrix4d expected{2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 2, 13, 1};
  EXPECT_EQ(scene.instances[0].world, expected);
  EXPECT_EQ(scene.positions[1].x, 3.0f);  // corner (1, 0, 0) -> (3, 2, 13)
  EXPECT_EQ(scene.positions[1].z, 13.0f);

  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.lights[0].name, "Lamp");
  EXPECT_EQ(scene.lights[0].node, 2);
  ASSERT_EQ(scene.cameras.size(), 1u);
  EXPECT_EQ(scene.cameras[0].name, "Main");
  EXPECT_EQ(scene.cameras[0].node, 0);
  EXPECT_EQ(scene.cameras[0].type, SceneCamera::Type::Perspective);
  EXPECT_EQ(scene.cameras[0].yfov, 0.7f);
  EXPECT_EQ(scene.cameras[0].aspect_ratio, 1.5f);
  EXPECT_EQ(scene.cameras[0].zfar, 50.0f);
  bool warned = false;
  for (const std::string& w : diagnostics.warnings)
    warned = warned || w.find("camera 1: invalid projection") != std::string::npos;
  EXPECT_TRUE(warned);
}

// alphaMode, alphaCutoff and baseColorFactor's alpha reach the material, and an RGBA base colour
// texture keeps its alpha (linear) for MASK; an OPAQUE material's texture drops it.
TEST(GltfImport, AlphaModeCutoffAndTextureAlphaReachTheMaterial) {
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_alpha_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string png = (dir / "rgba.png").string();
  {
    const unsigned char pixels[8] = {255, 255, 255, 0, 255, 255, 255, 255};  // 2 x 1: transparent, opaque
    auto out = OIIO::ImageOutput::create(png);
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(png, OIIO::ImageSpec(2, 1, 4, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels));
    out->close();
  }
  json document = triangle_document();
  document["images"] = json::array({{{"uri", "rgba.png"}}});
  document["textures"] = json::array({{{"source", 0}}});
  document["materials"] = json::parse(R"([
    {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8], "baseColorTexture": {"index": 0}, "metallicFactor": 0},
     "alphaMode": "MASK", "alphaCutoff": 0.3},
    {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}, "alphaMode": "BLEND"},
    {"pbrMetallicRoughness": {"metallicFactor": 0}}])");
  document["meshes"][0]["primitives"][0]["material"] = 0;
  const std::string path = (dir / "alpha.gltf").string();
  std::ofstream(path) << document.dump();
  Diagnostics diagnostics;
  const Scene scene = import_gltf(path, ImportOptions{}, diagnostics);
  std::filesystem::remove_all(dir);
  ASSERT_GE(scene.materials.size(), 3u);
  EXPECT_EQ(scene.materials[0].alpha_mode, Material::AlphaMode::Mask);
  EXPECT_FLOAT_EQ(scene.materials[0].alpha_cutoff, 0.3f);
  EXPECT_FLOAT_EQ(scene.materials[0].base_alpha, 0.8f);
  EXPECT_EQ(scene.materials[1].alpha_mode, Material::AlphaMode::Blend);
  EXPECT_FLOAT_EQ(scene.materials[1].base_alpha, 1.0f);
  EXPECT_EQ(scene.materials[2].alpha_mode, Material::AlphaMode::Opaque);
  ASSERT_EQ(scene.textures.size(), 1u);
  ASSERT_EQ(scene.textures[0].alpha.size(), 2u);
  EXPECT_EQ(scene.textures[0].alpha[0], 0.0f);
  EXPECT_EQ(scene.textures[0].alpha[1], 1.0f);
  // Coverage is base alpha times the bilinear texture alpha: the triangle has no TEXCOORD_0, so UV
  // (0, 0), which the default REPEAT sampler filters halfway between the right and the left texel.
  EXPECT_NEAR(surface_coverage(scene, 0, 0, 0), 0.8f * 0.5f, 1e-6f);
}

// A bad alphaCutoff or an alpha outside [0, 1] is an error naming the material.
TEST(GltfImport, BadAlphaValuesAreErrorsNamingTheMaterial) {
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_alpha_bad_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* material : {R"({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1.5]}})",
                               R"({"alphaMode": "MASK", "alphaCutoff": -1})"}) {
    json document = triangle_document();
    document["materials"] = json::array({json::parse(material)});
    document["meshes"][0]["primitives"][0]["material"] = 0;
    const std::string path = (dir / "bad_alpha.gltf").string();
    std::ofstream(path) << document.dump();
    Diagnostics diagnostics;
    try {
      import_gltf(path, ImportOptions{}, diagnostics);
      ADD_FAILURE() << material << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(e.element().find("material 0"), std::string::npos) << e.element();
    }
  }
  std::filesystem::remove_all(dir);
}

// COLOR_0 (normalized unsigned bytes, VEC4) reaches the scene per corner, linear; it multiplies the
// albedo; a COLOR_0 outside [0, 1] is an error naming its accessor.
TEST(GltfImport, VertexColoursMultiplyTheBaseColour) {
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_color_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto document_with_colours = [](const std::vector<unsigned char>& rgba) {
    json document = triangle_document();
    std::string uri = document["buffers"][0]["uri"];
    std::vector<unsigned char> data;
    append_floats(data, {0, 0, 0, 1, 0, 0, 0, 1, 0});
    append_floats(data, {0, 0, 1, 0, 0, 1, 0, 0, 1});
    append_floats(data, {0, 0, 1, 0, 0, 1});
    data.insert(data.end(), rgba.begin(), rgba.end());
    document["buffers"][0] = {{"byteLength", data.size()}, {"uri", "data:application/octet-stream;base64," + base64(data)}};
    document["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 96}, {"byteLength", rgba.size()}});
    document["accessors"].push_back(
        {{"bufferView", 2}, {"componentType", 5121}, {"normalized", true}, {"count", 3}, {"type", "VEC4"}});
    document["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 3;
    document["materials"] = json::parse(R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 1], "metallicFactor": 0}}])");
    document["meshes"][0]["primitives"][0]["material"] = 0;
    return document;
  };
  const std::string path = (dir / "colours.gltf").string();
  std::ofstream(path) << document_with_colours({255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0}).dump();
  Diagnostics diagnostics;
  const Scene scene = import_gltf(path, ImportOptions{}, diagnostics);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(scene.vertex_color.size(), 3u);
  ASSERT_EQ(scene.vertex_alpha.size(), 3u);
  EXPECT_EQ(scene.vertex_color[0].x, 1.0f);
  EXPECT_EQ(scene.vertex_color[0].y, 0.0f);
  EXPECT_NEAR(scene.vertex_alpha[1], 128.0f / 255.0f, 1e-6f);
  EXPECT_EQ(scene.vertex_alpha[2], 0.0f);
  // At corner 1 (b1 = 1): base colour (0.5, 1, 1) x COLOR_0 (0, 1, 0).
  const Vec3 albedo = diffuse_albedo(scene, 0, 1, 0);
  EXPECT_EQ(albedo.x, 0.0f);
  EXPECT_EQ(albedo.y, 1.0f);
  EXPECT_EQ(albedo.z, 0.0f);
  const Vec3 red = diffuse_albedo(scene, 0, 0, 0);
  EXPECT_EQ(red.x, 0.5f);
}

// The triangle of triangle_document with a one-texel PNG of (128, 64, 255) as `normalTexture`
// (and as base colour texture), and optionally a TANGENT attribute (1, 0, 0, w) at every vertex.
json normal_mapped_document(const std::filesystem::path& dir, std::optional<float> tangent_w, const json& normal_texture) {
  const std::string png = (dir / "normal.png").string();
  const unsigned char pixel[3] = {128, 64, 255};
  auto out = OIIO::ImageOutput::create(png);
  EXPECT_TRUE(out && out->open(png, OIIO::ImageSpec(1, 1, 3, OIIO::TypeDesc::UINT8)));
  EXPECT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixel));
  out->close();
  json d = triangle_document();
  d["images"] = json::array({{{"uri", "normal.png"}}});
  d["textures"] = json::array({{{"source", 0}}});
  d["materials"] = json::array(
      {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0}}}, {"normalTexture", normal_texture}}});
  d["meshes"][0]["primitives"][0]["material"] = 0;
  if (tangent_w) {
    std::vector<unsigned char> data;
    for (int v = 0; v < 3; ++v) append_floats(data, {1, 0, 0, *tangent_w});
    d["buffers"].push_back({{"byteLength", 48}, {"uri", "data:application/octet-stream;base64," + base64(data)}});
    d["bufferViews"].push_back({{"buffer", 1}, {"byteLength", 48}});
    d["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});
    d["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = 3;
  }
  return d;
}

Scene import_document(const std::filesystem::path& dir, const json& d) {
  const std::string path = (dir / "normal_mapped.gltf").string();
  std::ofstream(path) << d.dump();
  Diagnostics diagnostics;
  return import_gltf(path, ImportOptions{}, diagnostics);
}

void expect_frames(const Scene& scene, Vec3 tangent, float sign) {
  ASSERT_EQ(scene.tangents.size(), 3u);
  ASSERT_EQ(scene.tangent_signs.size(), 3u);
  for (size_t c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(scene.tangents[c][k], tangent[k], 1e-6f) << "corner " << c << " component " << k;
    EXPECT_EQ(scene.tangent_signs[c], sign) << "corner " << c;
  }
}

// normalTexture reaches the material (texture, texCoord, scale, KHR_texture_transform), decoded as
// data (no sRGB curve, unlike the same image as base colour); TANGENT turns with its node, and a
// mirroring node flips its handedness (the bitangent w cross(n, t) must stay the mirrored one).
TEST(GltfImport, NormalTextureAndTangentsReachTheScene) {
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_normal_map_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const json normal_texture = json::parse(
      R"({"index": 0, "texCoord": 1, "scale": 0.5, "extensions": {"KHR_texture_transform": {"offset": [0.25, 0]}}})");
  json d = normal_mapped_document(dir, 1.0f, normal_texture);
  d["nodes"][0]["rotation"] = {0, 0, std::sqrt(0.5), std::sqrt(0.5)};  // 90 degrees about +Z
  const Scene turned = import_document(dir, d);
  ASSERT_EQ(turned.triangle_count(), 1u);
  const Material& m = turned.materials[0];
  ASSERT_GE(m.normal_texture.texture, 0);
  EXPECT_EQ(m.normal_texture.transform.tex_coord, 1);
  EXPECT_EQ(m.normal_texture.transform.offset.x, 0.25f);
  EXPECT_EQ(m.normal_scale, 0.5f);
  ASSERT_EQ(turned.textures.size(), 2u);  // the image as sRGB colour and as data
  const Texture& normal_map = turned.textures[size_t(m.normal_texture.texture)];
  EXPECT_NEAR(normal_map.rgb[0], 128.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(normal_map.rgb[1], 64.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(turned.textures[size_t(m.base_color_texture.texture)].rgb[0], 0.2158605f, 1e-5f);  // sRGB 128
  expect_frames(turned, {0, 1, 0}, 1.0f);

  d = normal_mapped_document(dir, 1.0f, normal_texture);
  d["nodes"][0]["scale"] = {-1, 1, 1};
  const Scene mirrored = import_document(dir, d);
  for (const Vec3& n : mirrored.normals) EXPECT_EQ(n.z, 1.0f);
  expect_frames(mirrored, {-1, 0, 0}, -1.0f);

  // No normal map: no frames at all.
  const Scene plain = import_document(dir, triangle_document());
  EXPECT_TRUE(plain.tangents.empty());
  EXPECT_TRUE(plain.tangent_signs.empty());
  std::filesystem::remove_all(dir);
}

// Without TANGENT the frames follow the UVs the normal map reads, after its transform: on the
// triangle (0,0,0), (1,0,0), (0,1,0) with TEXCOORD_1 (0,0), (1,0), (0,1), u runs along +x and v
// along +y, so t = +x and the bitangent (towards decreasing v) is -y = -cross(n, t): w = -1. Rotated
// by pi/2 (uv' = (v, -u)), u' runs along +y: t = +y, and w = -1 again.
TEST(GltfImport, MissingTangentsAreGeneratedFromTheNormalMapUvs) {
  const auto dir = std::filesystem::temp_directory_path() / ("gltf_generated_tangent_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  expect_frames(import_document(dir, normal_mapped_document(dir, std::nullopt, json::parse(R"({"index": 0, "texCoord": 1})"))),
                {1, 0, 0}, -1.0f);
  const json rotated = json::parse(
      R"({"index": 0, "texCoord": 1, "extensions": {"KHR_texture_transform": {"rotation": 1.5707963267948966}}})");
  expect_frames(import_document(dir, normal_mapped_document(dir, std::nullopt, rotated)), {0, 1, 0}, -1.0f);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace exitance
