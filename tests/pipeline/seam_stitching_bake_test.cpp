// A baked scene with seams (a sphere with generated UVs over a floor, under a sky and a sun): the bake
// finds the sphere's seams and stitching cuts their mean discontinuity at least 5x, to below the
// seam texels' own relative standard error (issue 13, "Seams"). --seams off writes the same stats
// with nothing adjusted.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "support/sphere_over_floor_gltf.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

BakeOptions sphere_bake(const fs::path& dir, bool stitch) {
  BakeOptions options;
  options.input = (dir / "sphere.gltf").string();
  options.output = (dir / (stitch ? "stitched.bake" : "unstitched.bake")).string();
  options.sky = "0.3,0.35,0.45";
  options.atlas.texel_density = 12;
  options.lighting.spp = 64;
  options.lighting.seed = 7;
  options.backend.name = "cpu";
  options.probes_enabled = false;
  options.svo_enabled = false;
  options.stitch_seams = stitch;
  return options;
}

TEST(SeamStitchingBake, SphereSeamsDropAtLeastFiveFold) {
  const fs::path dir = fs::temp_directory_path() / ("exitance-test-seams-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  test::write_sphere_over_floor_gltf((dir / "sphere.gltf").string(), 48, 24, /*sun=*/true);

  Diagnostics diagnostics;
  const nlohmann::json stitched = run_bake(sphere_bake(dir, true), diagnostics)["seams"];
  ASSERT_TRUE(stitched.is_object());
  EXPECT_EQ(stitched["mode"], "stitch");
  EXPECT_GT(stitched["edges"].get<size_t>(), 10u);
  EXPECT_GT(stitched["texels_adjusted"].get<size_t>(), 0u);
  const double before = stitched["discontinuity_before"], after = stitched["discontinuity_after"];
  const double noise = stitched["texel_relative_error"];
  ASSERT_GT(before, 0.0);
  EXPECT_GE(before / std::max(after, 1e-12), 5.0) << "before " << before << " after " << after;
  EXPECT_LT(after, noise) << "after " << after << ", texel relative error " << noise;

  Diagnostics off_diagnostics;
  const nlohmann::json off = run_bake(sphere_bake(dir, false), off_diagnostics)["seams"];
  EXPECT_EQ(off["mode"], "off");
  EXPECT_EQ(off["texels_adjusted"], 0);
  EXPECT_EQ(off["edges"], stitched["edges"]);
  // Same seed, same texels: the unstitched bake measures what the stitched one found before.
  EXPECT_DOUBLE_EQ(off["discontinuity_after"].get<double>(), before);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
