// `bake` end to end through the loader: a white furnace written as glTF is baked with probes and
// the SVO, the bundle is opened with the loader library (as an engine would), and every product
// is checked against the closed form E/pi = Le / (1 - rho), M = pi * Le / (1 - rho):
// lightmap texels, probe irradiance for six normals, and SVO leaf exitance. The spread across
// independent probes / leaves gives the standard error of each mean (z-test within 4 SE).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/loader/bundle.h"
#include "scene_builder.h"
#include "support/independent_estimates.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

constexpr float kAlbedo = 0.5f;
constexpr float kEmission[3] = {0.5f, 0.25f, 0.125f};

fs::path write_furnace(const fs::path& dir) {
  samples::SceneBuilder builder;
  samples::Material material;
  material.baseColor = {kAlbedo, kAlbedo, kAlbedo};
  material.emissiveColor = {kEmission[0], kEmission[1], kEmission[2]};
  material.emissiveStrength = 1.0f;
  const auto id = builder.addMaterial(material);
  samples::MeshBuilder box;
  box.addBox({.center = {0, 1, 0}, .size = {2, 2, 2}}, id, samples::FaceDirection::Inward);
  builder.addMeshNode("Furnace", box);
  const fs::path path = dir / "furnace.gltf";
  builder.write(path.string());
  return path;
}

void expect_mean(const std::vector<double>& values, double exact, double max_relative_se, const char* what) {
  ASSERT_GE(values.size(), 8u) << what;
  const testing::MeanAndError m = testing::mean_and_standard_error(values);
  std::printf("[bundle] %-28s n %zu exact %.6g mean %.6g SE %.3g z %+.2f\n", what, m.count, exact, m.mean,
              m.standard_error, m.standard_error > 0 ? (m.mean - exact) / m.standard_error : 0.0);
  EXPECT_LE(std::fabs(m.mean - exact), 4.0 * m.standard_error + 1e-5 * exact) << what;
  EXPECT_LE(m.standard_error, max_relative_se * exact) << what << ": standard error implausibly large";
}

TEST(BundleEndToEnd, WhiteFurnaceThroughTheLoader) {
  const fs::path dir = fs::temp_directory_path() / ("exitance-test-furnace-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  BakeOptions options;
  options.input = write_furnace(dir).string();
  options.output = (dir / "out.bake").string();
  options.backend.name = "cpu";
  options.atlas.texel_density = 8;
  options.lighting.spp = 64;
  options.probe_spacing = 0.5f;
  options.probe_spp = 512;
  options.voxel_resolution = 8;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);

  const loader::Bundle bundle = loader::Bundle::open((dir / "out.bake").string());
  ASSERT_TRUE(bundle.has_probes());
  ASSERT_TRUE(bundle.has_svo());
  EXPECT_TRUE(fs::exists(dir / "out.bake" / "radiance.vdb"));
  const double exact_red = kEmission[0] / (1.0 - kAlbedo);

  // Lightmap: every fully covered texel of the page, and the loader's lookup at a chart texel.
  const formats::LightmapImage& page = bundle.page_image(0);
  std::vector<double> texels;
  const std::vector<float>& red = page.channels.at("R");
  const std::vector<float>& coverage = page.channels.at("A");
  for (size_t i = 0; i < red.size(); ++i)
    if (coverage[i] >= 1.0f) texels.push_back(red[i]);

  // Probes: a 4 x 4 x 4 grid inside the box (spacing 0.5 over [-1, 1]), none moved or skipped.
  const formats::ProbeGrid& grid = *bundle.probe_grid();
  EXPECT_EQ(grid.counts[0] * grid.counts[1] * grid.counts[2], 64u);
  std::vector<double> probe_values[6];
  const loader::Point3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const formats::ProbeRecord& r : grid.probes) {
    EXPECT_EQ(r.state, formats::ProbeState::Valid);
    for (int n = 0; n < 6; ++n) {
      const loader::ProbeIrradianceResult e = bundle.probe_irradiance_over_pi(r.position, normals[n]);
      ASSERT_TRUE(e.usable);
      probe_values[n].push_back(e.irradiance_over_pi[0]);
    }
  }
  for (int n = 0; n < 6; ++n) expect_mean(probe_values[n], exact_red, 0.02, "probe E/pi (red)");

  // SVO: every leaf lies on a wall; its front side carries M = pi Le / (1 - rho).
  const formats::SparseVoxelOctree& svo = *bundle.octree();
  EXPECT_EQ(svo.depth, 3u);
  std::vector<double> leaves;
  for (uint32_t i = svo.level_begin[svo.depth]; i < svo.level_begin[svo.depth + 1]; ++i)
    if (svo.nodes[i].flags & formats::kSvoFrontLit) leaves.push_back(formats::svo_node_exitance(svo, i, 0)[0]);
  expect_mean(leaves, 3.14159265358979 * exact_red, 0.02, "SVO leaf exitance (red)");
  expect_mean(texels, exact_red, 0.02, "lightmap E/pi (red)");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
