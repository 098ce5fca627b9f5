// End to end (issue 13): a glTF cube with no TEXCOORD_1 bakes with generated lightmap UVs, a warning
// naming the mesh, the manifest recording them honestly, and a finite, non-zero lightmap.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/uvgen/scene_uv_generation.h"
#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/lightmap_exr.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

// Bakes the hostile corpus' cube without TEXCOORD_1 into `output` on the CPU at 16 texels per unit,
// `spp` samples, without probes or the SVO.
BakeOptions cube_without_texcoord1(const fs::path& output, uint32_t spp) {
  BakeOptions options;
  options.input = std::string(EXITANCE_HOSTILE_DIR) + "/mesh_without_texcoord1.gltf";
  options.output = output.string();
  options.atlas.texel_density = 16;
  options.lighting.spp = spp;
  options.backend.name = "cpu";
  options.probes_enabled = false;
  options.svo_enabled = false;
  return options;
}

TEST(GeneratedUvBake, CubeWithoutTexcoord1BakesWithAWarning) {
  const fs::path out = fs::temp_directory_path() / ("exitance-test-generated-uv-" + std::to_string(::getpid()));
  fs::remove_all(out);
  BakeOptions options = cube_without_texcoord1(out, 4);
  options.sky = "1,1,1";
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

// --write-gltf: the written file has the generated UVs as TEXCOORD_1 (it imports without generating),
// the same triangles in the same order, and exactly the UVs the bake generated.
TEST(GeneratedUvBake, WriteGltfHasTheGeneratedTexcoord1) {
  const fs::path dir = fs::temp_directory_path() / ("exitance-test-write-gltf-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  BakeOptions options = cube_without_texcoord1(dir / "out.bake", 1);
  options.write_gltf = (dir / "with_uvs.gltf").string();
  Diagnostics diagnostics;
  run_bake(options, diagnostics);

  Diagnostics d;
  std::vector<MeshWithoutLightmapUvs> missing;
  Scene generated = import_gltf(options.input, {}, d, &missing);
  generate_missing_lightmap_uvs(generated, missing, 16, options.atlas.max_page - 2 * options.atlas.padding, {});
  const Scene written = import_gltf(options.write_gltf, {}, d);  // no generation: TEXCOORD_1 is there
  ASSERT_EQ(written.triangle_count(), generated.triangle_count());
  for (size_t c = 0; c < written.positions.size(); ++c) {
    EXPECT_EQ(written.positions[c].x, generated.positions[c].x);
    EXPECT_EQ(written.positions[c].y, generated.positions[c].y);
    EXPECT_EQ(written.positions[c].z, generated.positions[c].z);
    EXPECT_EQ(written.lightmap_uv[c].x, generated.lightmap_uv[c].x);
    EXPECT_EQ(written.lightmap_uv[c].y, generated.lightmap_uv[c].y);
  }
  fs::remove_all(dir);
}

// The bundle cache (issue 12) keys a bake before UV generation, which the scene and options
// determine: a second bake reuses the first, still writes --write-gltf, and --uv generate is a new key.
TEST(GeneratedUvBake, CachedBakeIsReusedAndStillWritesTheGltf) {
  const fs::path dir = fs::temp_directory_path() / ("exitance-test-uv-cache-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  auto options_for = [&](const std::string& out) {
    BakeOptions options = cube_without_texcoord1(dir / out, 1);
    options.cache_directory = (dir / "cache").string();
    return options;
  };
  Diagnostics first_diagnostics, second_diagnostics, third_diagnostics;
  const nlohmann::json first = run_bake(options_for("a.bake"), first_diagnostics);
  BakeOptions second_options = options_for("b.bake");
  second_options.write_gltf = (dir / "with_uvs.gltf").string();
  const nlohmann::json second = run_bake(second_options, second_diagnostics);
  EXPECT_FALSE(first["cache"]["reused"].get<bool>());
  EXPECT_TRUE(second["cache"]["reused"].get<bool>());
  EXPECT_EQ(second_diagnostics.warnings, first_diagnostics.warnings);
  Diagnostics d;
  const Scene written = import_gltf(second_options.write_gltf, {}, d);  // has TEXCOORD_1
  EXPECT_EQ(written.triangle_count(), 12u);
  BakeOptions generate_all = options_for("c.bake");
  generate_all.import.generate_lightmap_uvs = true;
  const nlohmann::json third = run_bake(generate_all, third_diagnostics);
  EXPECT_FALSE(third["cache"]["reused"].get<bool>());
  EXPECT_NE(third["cache"]["key"], first["cache"]["key"]);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
