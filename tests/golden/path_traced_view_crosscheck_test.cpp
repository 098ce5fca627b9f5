// The path-traced view on the Vulkan backend (what exitance-view --path-traced runs) against the same
// view on the CPU reference (what the golden tests use): the same camera-ray batch, independent seeds;
// per region of 16 consecutive pixels, a z-test with both estimators' variances (|z| < 4,
// support/lightmap_comparison.h). Tiny, for lavapipe. Validation layer on; no Vulkan device: SKIP.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/view/path_traced_view.h"
#include "exitance/runtime/view/view_scene.h"
#include "sample_scenes.h"
#include "support/fresh_temp_dir.h"
#include "support/lightmap_comparison.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

TEST(PathTracedView, VulkanAgreesWithTheCpuReference) {
  const fs::path dir = testing::fresh_temp_dir("path-traced-view-crosscheck");
  samples::SceneBuilder builder;
  samples::buildCornellRoom(builder);
  builder.write((dir / "cornell_room.gltf").string());
  BakeOptions options;
  options.input = (dir / "cornell_room.gltf").string();
  options.output = (dir / "cornell_room.bake").string();
  options.backend.name = "cpu";
  options.atlas.texel_density = 2;  // only scene.bin matters here
  options.lighting.spp = 1;
  options.probes_enabled = false;
  options.svo_enabled = false;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);

  const view::ViewScene scene = view::open_view_scene((dir / "cornell_room.bake").string());
  const view::PinholeCamera camera = view::look_at_camera({0, 2, 1.9f}, {0, 1.7f, -2}, {0, 1, 0}, 1.1);
  const std::shared_ptr<const LightingScene> lighting = view::lighting_scene_of(scene);
  constexpr int kSide = 16;
  IntegratorSettings settings;
  settings.spp = 64;
  settings.recorded_bounces = 1;
  {
    CREATE_VULKAN_OR_SKIP(vk, lighting, VulkanDeviceOptions{});
    settings.seed = 1001;
    const view::PathTracedView gpu = view::render_path_traced_view(scene, camera, kSide, kSide, *vk.operator->(), settings);
    settings.seed = 2002;
    const view::PathTracedView cpu =
        view::render_path_traced_view(scene, camera, kSide, kSide, CpuReferenceIntegrator(*lighting->source), settings);
    EXPECT_GT(cpu.estimate.texels.size(), size_t(kSide * kSide * 9 / 10));
    testing::compare_estimates(gpu.estimate, cpu.estimate, 16, "path-traced view 16x16");

    // exitance-view --path-traced is this Vulkan view: same seed and samples, the same pixels up to
    // the order of float sums.
    const std::string out = (dir / "view.exr").string();
    const std::string command = std::string(EXITANCE_VIEW) + " " + (dir / "cornell_room.bake").string() +
                                " --look-from 0,2,1.9 --look-at 0,1.7,-2 --yfov 1.1 --size 16 --path-traced --spp 64 --seed 1001 -o " +
                                out + " 2>/dev/null";
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
    const formats::LightmapImage exr = formats::read_lightmap_exr(out);
    ASSERT_EQ(exr.width, kSide);
    ASSERT_EQ(exr.height, kSide);
    for (int c = 0; c < 3; ++c) {
      const std::vector<float>& channel = exr.channels.at(c == 0 ? "R" : (c == 1 ? "G" : "B"));
      for (size_t p = 0; p < channel.size(); ++p) {
        const float expected = gpu.image.rgb[p * 3 + size_t(c)];
        ASSERT_NEAR(channel[p], expected, 1e-4f * (std::fabs(expected) + 1e-3f)) << "pixel " << p << " channel " << c;
      }
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
