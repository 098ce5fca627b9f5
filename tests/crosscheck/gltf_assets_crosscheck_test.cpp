// Issue 13's acceptance case, end to end from a glTF file: a scene with no lightmap UVs (TEXCOORD_0
// only, so bake generates TEXCOORD_1), a base-colour texture, a MASK cut-out fence and an image sky
// (an .hdr equirectangular map) bakes on the Vulkan backend (lavapipe here) and on the CPU reference
// with the same result: per region of texels of the written lightmap pages, the luminance of the two
// bundles agrees within their own estimated standard errors (|z| < 4.5).
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/sphere_over_floor_gltf.h"
#include "support/vulkan_device_available.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

using testing::has_vulkan_device;

// A 6 m textured floor, a back wall, and a 2 x 1 m fence of four vertical slats (a MASK texture of
// alternating opaque and clear columns) standing on the floor; TEXCOORD_0 only.
void write_scene(const fs::path& dir) {
  // Checker base colour for the floor and wall (2 x 2, repeated), and the fence's RGBA slats (8 x 1).
  const uint8_t checker[2 * 2 * 3] = {230, 200, 160, 90, 120, 200, 90, 120, 200, 230, 200, 160};
  stbi_write_png((dir / "checker.png").string().c_str(), 2, 2, 3, checker, 2 * 3);
  uint8_t slats[8 * 4];
  for (int x = 0; x < 8; ++x) {
    const uint8_t opaque = x % 2 == 0 ? 255 : 0;
    const uint8_t rgba[4] = {200, 80, 60, opaque};
    std::copy(rgba, rgba + 4, slats + 4 * x);
  }
  stbi_write_png((dir / "slats.png").string().c_str(), 8, 1, 4, slats, 8 * 4);

  struct Quad {
    const char* name;
    std::vector<float> positions, normals, uvs;
    int material;
  };
  const std::vector<Quad> quads = {
      {"Floor", {-3, 0, -3, -3, 0, 3, 3, 0, 3, 3, 0, -3}, {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, {0, 0, 0, 3, 3, 3, 3, 0}, 0},
      {"Wall", {-3, 0, -3, 3, 0, -3, 3, 2, -3, -3, 2, -3}, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, {0, 1, 3, 1, 3, 0, 0, 0}, 0},
      {"Fence", {-1, 0, 0, 1, 0, 0, 1, 1, 0, -1, 1, 0}, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, {0, 1, 1, 1, 1, 0, 0, 0}, 1}};
  std::vector<uint8_t> buffer;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array(), meshes = nlohmann::json::array(),
                 nodes = nlohmann::json::array();
  auto append = [&](const void* data, size_t bytes, int target) {
    while (buffer.size() % 4) buffer.push_back(0);
    views.push_back({{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", bytes}, {"target", target}});
    buffer.insert(buffer.end(), static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + bytes);
    return views.size() - 1;
  };
  const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
  for (const Quad& q : quads) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t k = 0; k < q.positions.size(); ++k)
      lo[k % 3] = std::min(lo[k % 3], q.positions[k]), hi[k % 3] = std::max(hi[k % 3], q.positions[k]);
    const size_t first = accessors.size();
    accessors.push_back({{"bufferView", append(q.positions.data(), q.positions.size() * 4, 34962)},
                         {"componentType", 5126}, {"count", 4}, {"type", "VEC3"},
                         {"min", {lo[0], lo[1], lo[2]}}, {"max", {hi[0], hi[1], hi[2]}}});
    accessors.push_back({{"bufferView", append(q.normals.data(), q.normals.size() * 4, 34962)},
                         {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}});
    accessors.push_back({{"bufferView", append(q.uvs.data(), q.uvs.size() * 4, 34962)},
                         {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}});
    accessors.push_back({{"bufferView", append(indices, sizeof indices, 34963)},
                         {"componentType", 5125}, {"count", 6}, {"type", "SCALAR"}});
    nlohmann::json primitive = {{"attributes", {{"POSITION", first}, {"NORMAL", first + 1}, {"TEXCOORD_0", first + 2}}},
                                {"indices", first + 3}, {"material", q.material}};
    nodes.push_back({{"name", q.name}, {"mesh", meshes.size()}});
    meshes.push_back({{"name", q.name}, {"primitives", nlohmann::json::array({primitive})}});
  }
  nlohmann::json gltf = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 1, 2}}}}},
      {"nodes", nodes},
      {"meshes", meshes},
      {"images", {{{"uri", "checker.png"}}, {{"uri", "slats.png"}}}},
      {"samplers", {{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 10497}, {"wrapT", 10497}}}},
      {"textures", {{{"source", 0}, {"sampler", 0}}, {{"source", 1}, {"sampler", 0}}}},
      {"materials",
       {{{"name", "Checker"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}},
        {{"name", "Slats"},
         {"alphaMode", "MASK"},
         {"alphaCutoff", 0.5},
         {"doubleSided", true},
         {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}, {"metallicFactor", 0.0}}}}}},
      {"accessors", accessors},
      {"bufferViews", views},
      {"buffers", {{{"byteLength", buffer.size()},
                    {"uri", "data:application/octet-stream;base64," + test::base64(buffer)}}}}};
  std::ofstream(dir / "assets.gltf") << gltf.dump();

  // Equirectangular sky, 32 x 16 (row 0 = zenith): a blue upper hemisphere with a bright patch
  // low in the -Z half (behind the wall), a bright one in the +Z half (casting the fence's slats
  // onto the floor), and a dark ground.
  const int w = 32, h = 16;
  std::vector<float> sky(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float r = 0.05f, g = 0.05f, b = 0.05f;
      if (y < h / 2) r = 0.3f, g = 0.45f, b = 0.8f;
      if (y >= 4 && y < 6 && x >= 0 && x < 3) r = g = b = 40.0f;  // u near 0: looking along +Z
      float* p = &sky[(size_t(y) * w + x) * 3];
      p[0] = r, p[1] = g, p[2] = b;
    }
  stbi_write_hdr((dir / "sky.hdr").string().c_str(), w, h, 3, sky.data());
}

BakeOptions assets_bake(const fs::path& dir, const std::string& backend, uint32_t seed) {
  BakeOptions options;
  options.input = (dir / "assets.gltf").string();
  options.output = (dir / (backend + ".bake")).string();
  options.sky = (dir / "sky.hdr").string();
  options.backend.name = backend;
  options.lighting.integrator = IntegratorMode::Path;
  options.integrator_auto = false;
  options.atlas.texel_density = 6;
  options.lighting.spp = 64;
  options.lighting.seed = seed;
  options.probes_enabled = false;
  options.svo_enabled = false;
  return options;
}

float luminance_of(const formats::LightmapImage& page, size_t at) {
  return 0.2126f * page.channels.at("R")[at] + 0.7152f * page.channels.at("G")[at] + 0.0722f * page.channels.at("B")[at];
}

TEST(GltfAssetsCrosscheck, GeneratedUvsTexturesCutoutsAndImageSkyAgreeOnBothBackends) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = fs::temp_directory_path() / ("exitance-assets-crosscheck-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_scene(dir);

  Diagnostics cpu_diagnostics, vulkan_diagnostics;
  const nlohmann::json cpu = run_bake(assets_bake(dir, "cpu", 1), cpu_diagnostics);
  const nlohmann::json vulkan = run_bake(assets_bake(dir, "vulkan", 2), vulkan_diagnostics);
  const nlohmann::json manifest = nlohmann::json::parse(std::ifstream(dir / "vulkan.bake" / "manifest.json"));
  EXPECT_EQ(manifest["settings"]["backend"], "vulkan");
  ASSERT_TRUE(manifest["stats"].contains("generated_lightmap_uvs")) << "TEXCOORD_1 was not generated";

  size_t regions = 0, texels_compared = 0;
  double worst_z = 0;
  for (const auto& page : manifest["pages"]) {
    const std::string file = page["file"];
    const formats::LightmapImage a = formats::read_lightmap_exr((dir / "cpu.bake" / file).string());
    const formats::LightmapImage b = formats::read_lightmap_exr((dir / "vulkan.bake" / file).string());
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    // Regions of 32 fully covered traced texels in row order; variance of a texel's mean from its
    // written relative standard error (error.Y = SE / (Y + floor): SE >= error.Y x Y is a slight
    // underestimate on dark texels, and over Sobol samples error.Y itself errs high).
    double sum_a = 0, sum_b = 0, var_a = 0, var_b = 0;
    size_t in_region = 0;
    auto close_region = [&] {
      if (in_region == 0) return;
      const double se = std::sqrt(var_a + var_b), diff = std::fabs(sum_a - sum_b);
      const double z = se > 0 ? diff / se : (diff > 1e-6 * std::fabs(sum_a) ? INFINITY : 0.0);
      worst_z = std::max(worst_z, z);
      EXPECT_LT(z, 4.5) << file << " region " << regions << ": CPU " << sum_a / double(in_region) << " Vulkan "
                        << sum_b / double(in_region) << " SE " << se / double(in_region);
      ++regions;
      sum_a = sum_b = var_a = var_b = 0;
      in_region = 0;
    };
    for (size_t at = 0; at < a.channels.at("R").size(); ++at) {
      if (!(a.channels.at("A")[at] >= 1.0f && b.channels.at("A")[at] >= 1.0f)) continue;
      if (!(a.channels.at("valid")[at] > 0 && b.channels.at("valid")[at] > 0)) continue;
      const double ya = luminance_of(a, at), yb = luminance_of(b, at);
      ASSERT_TRUE(std::isfinite(ya) && std::isfinite(yb));
      const double sa = a.channels.at("error.Y")[at] * ya, sb = b.channels.at("error.Y")[at] * yb;
      sum_a += ya, sum_b += yb, var_a += sa * sa, var_b += sb * sb;
      ++texels_compared;
      if (++in_region == 32) close_region();
    }
    close_region();
  }
  std::printf("assets crosscheck: %zu texels in %zu regions, worst |z| %.2f\n", texels_compared, regions, worst_z);
  EXPECT_GE(regions, 20u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
