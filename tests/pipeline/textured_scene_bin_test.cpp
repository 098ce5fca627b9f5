// scene.bin version 2 end to end: the Cornell room made textured (a base colour texture read
// through TEXCOORD_1 with a KHR_texture_transform, an emissive texture), vertex-coloured (COLOR_0),
// masked (alphaMode MASK) and lit by an environment-map sky is baked on the CPU; the bundle has a
// scene.bin, and lighting the scene and G-buffer restored from it with the CPU reference at the
// bake's seed and samples gives the bake's lightmap pages bit for bit. So the stored textures,
// vertex colours and sky are exactly what the bake lit with.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// cornell_room.gltf (and its buffer) copied into `dir` and edited as described above.
fs::path write_textured_cornell(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(EXITANCE_SAMPLE_DIR))
    if (entry.path().filename().string().rfind("cornell_room", 0) == 0 && entry.is_regular_file())
      fs::copy_file(entry.path(), dir / entry.path().filename());
  nlohmann::json gltf = nlohmann::json::parse(read_text(dir / "cornell_room.gltf"));
  // The 4 x 4 PNG of tests/badinput/hostile/valid_texture.gltf (embedded as a data URI).
  const nlohmann::json texture_source = nlohmann::json::parse(read_text(EXITANCE_HOSTILE_DIR "/valid_texture.gltf"));
  gltf["images"] = texture_source["images"];
  gltf["samplers"] = {{{"wrapS", 33648}, {"wrapT", 33071}}};  // mirrored repeat, clamp to edge
  gltf["textures"] = {{{"source", 0}, {"sampler", 0}}};
  gltf["extensionsUsed"].push_back("KHR_texture_transform");
  nlohmann::json& materials = gltf["materials"];
  size_t emissive = materials.size(), diffuse = materials.size();
  for (size_t i = 0; i < materials.size(); ++i) {
    const bool emits = materials[i].contains("emissiveFactor");
    if (emits && emissive == materials.size()) emissive = i;
    if (!emits && diffuse == materials.size()) diffuse = i;
  }
  EXPECT_LT(emissive, materials.size());
  EXPECT_LT(diffuse, materials.size());
  nlohmann::json& walls = materials[diffuse];
  walls["pbrMetallicRoughness"]["baseColorTexture"] = {
      {"index", 0},
      {"texCoord", 1},
      {"extensions", {{"KHR_texture_transform", {{"scale", {3.0, 2.0}}, {"rotation", 0.4}, {"offset", {0.1, 0.0}}}}}}};
  walls["pbrMetallicRoughness"]["baseColorFactor"] = {0.9, 0.9, 0.9, 0.8};
  walls["alphaMode"] = "MASK";
  walls["alphaCutoff"] = 0.5;
  materials[emissive]["emissiveTexture"] = {{"index", 0}};
  // COLOR_0 (RGBA floats) on the first mesh's first primitive, from a buffer of its own.
  nlohmann::json& primitive = gltf["meshes"][0]["primitives"][0];
  const size_t count = gltf["accessors"][primitive["attributes"]["POSITION"].get<size_t>()]["count"].get<size_t>();
  std::vector<float> colours;
  for (size_t v = 0; v < count; ++v)
    for (float c : {0.5f + 0.5f * float(v % 3) / 2, 0.75f, 1.0f - 0.25f * float(v % 2), 1.0f}) colours.push_back(c);
  std::ofstream(dir / "colours.bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(colours.data()), std::streamsize(colours.size() * sizeof(float)));
  gltf["buffers"].push_back({{"uri", "colours.bin"}, {"byteLength", colours.size() * sizeof(float)}});
  gltf["bufferViews"].push_back(
      {{"buffer", gltf["buffers"].size() - 1}, {"byteOffset", 0}, {"byteLength", colours.size() * sizeof(float)}});
  gltf["accessors"].push_back(
      {{"bufferView", gltf["bufferViews"].size() - 1}, {"componentType", 5126}, {"count", count}, {"type", "VEC4"}});
  primitive["attributes"]["COLOR_0"] = gltf["accessors"].size() - 1;
  const fs::path path = dir / "textured_cornell.gltf";
  std::ofstream(path) << gltf.dump();

  formats::LightmapImage sky;  // an equirectangular sky: bright blue above, dim orange below
  sky.width = 16;
  sky.height = 8;
  for (const char* c : {"R", "G", "B"}) sky.channels[c].resize(16 * 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      const size_t i = size_t(y * 16 + x);
      sky.channels["R"][i] = y < 4 ? 0.2f : 0.6f;
      sky.channels["G"][i] = y < 4 ? 0.4f + 0.02f * float(x) : 0.3f;
      sky.channels["B"][i] = y < 4 ? 1.5f : 0.1f;
    }
  formats::write_lightmap_exr((dir / "sky.exr").string(), sky);
  return path;
}

TEST(TexturedSceneBin, CpuRelightFromSceneBinReproducesTheBake) {
  const fs::path dir = testing::fresh_temp_dir("textured-scene-bin");
  BakeOptions options;
  options.input = write_textured_cornell(dir).string();
  options.output = (dir / "textured.bake").string();
  options.sky = (dir / "sky.exr").string();
  options.backend.name = "cpu";
  options.atlas.texel_density = 8;
  options.lighting.spp = 4;
  options.lighting.seed = 5;
  options.adaptive_request = AdaptiveRequest::Off;
  options.skip_sealed_texels = false;  // a relight lights every live texel
  options.stitch_seams = false;        // compare the assembled pages themselves
  options.probes_enabled = false;
  options.svo_enabled = false;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  for (const std::string& w : diagnostics.warnings) EXPECT_EQ(w.find("scene.bin not written"), std::string::npos) << w;

  const fs::path bundle = dir / "textured.bake";
  ASSERT_TRUE(fs::exists(bundle / "scene.bin"));
  const nlohmann::json manifest = nlohmann::json::parse(read_text(bundle / "manifest.json"));
  EXPECT_EQ(manifest["scene"]["format_version"], formats::kSceneFormatVersion);
  const formats::SceneFile file = formats::read_scene_file((bundle / "scene.bin").string());
  EXPECT_EQ(file.textures.size(), 1u);
  EXPECT_FALSE(file.vertex_color.empty());
  EXPECT_NE(file.sky_environment.width, 0u);
  const PersistedScene restored = restore_scene(file);

  IntegratorSettings settings = options.lighting;
  settings.adaptive = false;
  const LightmapEstimate relit = CpuReferenceIntegrator(restored.scene).bake(restored.gbuffer, settings);
  AssemblyOptions assembly;
  assembly.dilation_texels = std::max(2, options.atlas.padding * 2);  // as the bundle writer
  const std::vector<formats::LightmapImage> pages = assemble_lightmap_pages(restored.gbuffer, relit, assembly);
  ASSERT_EQ(pages.size(), restored.gbuffer.pages.size());
  size_t compared = 0, differing = 0;
  for (size_t p = 0; p < pages.size(); ++p) {
    // Through the same EXR writer, so both sides are stored at the same precision.
    const std::string relit_path = (dir / ("relit-" + std::to_string(p) + ".exr")).string();
    formats::write_lightmap_exr(relit_path, pages[p]);
    const formats::LightmapImage a = formats::read_lightmap_exr((bundle / ("lightmap-" + std::to_string(p) + ".exr")).string());
    const formats::LightmapImage b = formats::read_lightmap_exr(relit_path);
    for (const char* c : {"R", "G", "B", "A"}) {
      const std::vector<float>&x = a.channels.at(c), &y = b.channels.at(c);
      ASSERT_EQ(x.size(), y.size());
      for (size_t i = 0; i < x.size(); ++i, ++compared)
        if (std::memcmp(&x[i], &y[i], sizeof(float)) != 0 && ++differing <= 5)
          ADD_FAILURE() << "page " << p << " channel " << c << " texel " << i << ": bake " << x[i] << ", relit " << y[i];
    }
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(compared, 1000u);
  // The comparison can fail: without the stored textures, vertex colours and sky most texels change.
  Scene plain = restored.scene;
  plain.textures.clear();
  plain.vertex_color.clear();
  plain.vertex_alpha.clear();
  plain.sky.environment = Texture{};
  for (Material& m : plain.materials) m.base_color_texture.texture = m.emissive_texture.texture = -1;
  const LightmapEstimate untextured = CpuReferenceIntegrator(plain).bake(restored.gbuffer, settings);
  size_t changed = 0;
  for (size_t i = 0; i < relit.texels.size(); ++i) {
    const Vec3 x = relit.mean_total(i), y = untextured.mean_total(i);
    changed += std::memcmp(&x, &y, sizeof(Vec3)) != 0;
  }
  EXPECT_GT(changed, relit.texels.size() / 2);
  std::printf("[textured scene.bin] %zu bytes, %zu live texels, %zu channel values compared, %zu differ; "
              "%zu texels change without the textures\n",
              size_t(fs::file_size(bundle / "scene.bin")), restored.gbuffer.texels.size(), compared, differing, changed);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
