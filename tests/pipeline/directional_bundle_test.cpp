// bake --directional sh1 end to end (issue 14): the nine documented channels sh1.x.R .. sh1.z.B are in
// every page and the manifest, settings.directional says "sh1", and under a constant sky an upward
// plane's layers read L1 = (0, L/2, 0) within the noise (docs/bundle.md, "Directional layers").
// Without the option there are no sh1 channels and no settings.directional.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/lightmap_exr.h"
#include "scene_builder.h"
#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using samples::Quad;

fs::path write_floor(const fs::path& dir) {
  samples::SceneBuilder builder;
  samples::Material grey;
  grey.baseColor = {0.5f, 0.5f, 0.5f};
  const auto material = builder.addMaterial(grey);
  samples::MeshBuilder floor;
  floor.addQuad(Quad::axisAligned({-2, 0, -2}, {2, 0, 2}, {0, 1, 0}), material);
  builder.addMeshNode("Floor", floor);
  const fs::path path = dir / "floor.gltf";
  builder.write(path.string());
  return path;
}

nlohmann::json bake_floor(const fs::path& dir, const std::string& name, bool directional) {
  BakeOptions options;
  options.input = write_floor(dir).string();
  options.output = (dir / name).string();
  options.backend.name = "cpu";
  options.sky = "0.25,0.5,1";
  options.atlas.texel_density = 8;
  options.lighting.spp = 32;
  options.probes_enabled = false;
  options.svo_enabled = false;
  if (directional) options.lighting.directional = DirectionalMode::Sh1;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  std::ifstream manifest_file(dir / name / "manifest.json");
  return nlohmann::json::parse(manifest_file);
}

const char* const kSh1Channels[9] = {"sh1.x.R", "sh1.x.G", "sh1.x.B", "sh1.y.R", "sh1.y.G",
                                     "sh1.y.B", "sh1.z.R", "sh1.z.G", "sh1.z.B"};

TEST(DirectionalBundle, Sh1ChannelsRoundTrip) {
  const fs::path dir = testing::fresh_temp_dir("directional-bundle");
  const nlohmann::json manifest = bake_floor(dir, "sh1.bake", true);
  EXPECT_EQ(manifest["settings"]["directional"], "sh1");
  ASSERT_EQ(manifest["pages"].size(), 1u);
  const auto listed = manifest["pages"][0]["channels"].get<std::vector<std::string>>();
  const formats::LightmapImage page =
      formats::read_lightmap_exr((dir / "sh1.bake" / manifest["pages"][0]["file"].get<std::string>()).string());
  const std::vector<float>& coverage = page.channels.at("A");
  const float sky[3] = {0.25f, 0.5f, 1.0f};
  for (int k = 0; k < 9; ++k) {
    const std::string name = kSh1Channels[k];
    EXPECT_NE(std::find(listed.begin(), listed.end(), name), listed.end()) << name << " not in the manifest";
    ASSERT_TRUE(page.channels.count(name)) << name << " not in the EXR";
    const std::vector<float>& values = page.channels.at(name);
    // Per channel: the covered texels' mean against L n0 / 2, within 4 standard errors of the
    // per-texel spread (the texels are independent estimates of the same value).
    const int axis = k / 3;
    const double exact = axis == 1 ? 0.5 * sky[k % 3] : 0.0;
    double sum = 0, squares = 0;
    size_t n = 0;
    for (size_t i = 0; i < values.size(); ++i) {
      ASSERT_TRUE(std::isfinite(values[i])) << name << " texel " << i;
      if (coverage[i] < 1) continue;  // whole texels: partly covered ones are dilation-blended
      sum += values[i], squares += double(values[i]) * values[i], ++n;
    }
    ASSERT_GT(n, 100u);
    const double mean = sum / double(n);
    const double se = std::sqrt(std::max(0.0, squares / double(n) - mean * mean) / double(n - 1));
    EXPECT_LE(std::fabs(mean - exact), 4 * se + 1e-6) << name << ": mean " << mean << " exact " << exact << " SE " << se;
  }
}

TEST(DirectionalBundle, OffWritesNoSh1Channels) {
  const fs::path dir = testing::fresh_temp_dir("directional-off");
  const nlohmann::json manifest = bake_floor(dir, "off.bake", false);
  EXPECT_FALSE(manifest["settings"].contains("directional"));
  const formats::LightmapImage page =
      formats::read_lightmap_exr((dir / "off.bake" / manifest["pages"][0]["file"].get<std::string>()).string());
  for (const char* name : kSh1Channels) EXPECT_FALSE(page.channels.count(name)) << name;
}

}  // namespace
}  // namespace exitance
