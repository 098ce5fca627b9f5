// End to end (issue 13): a glTF cube with no TEXCOORD_1 bakes with generated lightmap UVs, a warning
// naming the mesh, the manifest recording them honestly, and a finite, non-zero lightmap.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/lightmap_exr.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

TEST(GeneratedUvBake, CubeWithoutTexcoord1BakesWithAWarning) {
  const fs::path out = fs::temp_directory_path() / ("exitance-test-generated-uv-" + std::to_string(::getpid()));
  fs::remove_all(out);
  BakeOptions options;
  options.input = std::string(EXITANCE_HOSTILE_DIR) + "/mesh_without_texcoord1.gltf";
  options.output = out.string();
  options.sky = "1,1,1";
  options.atlas.texel_density = 16;
  options.lighting.spp = 4;
  options.backend.name = "cpu";
  options.probes_enabled = false;
  options.svo_enabled = false;
  Diagnostics diagnostics;
  const nlohmann::json report = run_bake(options, diagnostics);

  bool warned = false;
  for (const std::string& w : diagnostics.warnings)
    warned = warned || w.find("mesh 0 'Cube': no TEXCOORD_1; generated lightmap UVs: 6 charts") != std::string::npos;
  EXPECT_TRUE(warned);
  ASSERT_EQ(report["generated_lightmap_uvs"].size(), 1u);
  EXPECT_EQ(report["generated_lightmap_uvs"][0]["charts"], 6);

  std::ifstream file(out / "manifest.json");
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const formats::BundleManifest manifest = formats::parse_bundle_manifest(text, "manifest.json");
  ASSERT_TRUE(manifest.settings);
  EXPECT_EQ(manifest.settings->generated_uv_meshes, std::vector<uint32_t>{0});
  EXPECT_FALSE(manifest.settings->lightmap_uv_generate);

  const formats::LightmapImage page = formats::read_lightmap_exr((out / manifest.pages[0].file).string());
  const auto& r = page.channels.at("R");
  const auto& a = page.channels.at("A");
  size_t lit = 0, covered = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(std::isfinite(r[i]));
    if (a[i] <= 0) continue;
    ++covered;
    lit += r[i] > 0;
  }
  EXPECT_GT(covered, 6u * 16 * 16 / 2);  // six unit faces at 16 texels per unit
  EXPECT_GT(lit, covered / 2);
  fs::remove_all(out);
}

}  // namespace
}  // namespace exitance
