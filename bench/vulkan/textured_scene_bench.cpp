// Vulkan backend vs the CPU reference on the textured, masked, blended, vertex-coloured scene of the
// cross-checks (tests/support/textured_scenes.h) with a denser texel grid, and on the same scene with
// its per-point data stripped (constant factors, OPAQUE, no COLOR_0): seconds, rays per second and
// agreement (worst per-region |z| over groups of 16 texels, relMSE). A 1-spp bake warms the
// pipelines up first. Results: bench/results/gpu-textures.md.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/textured_scenes.h"

using namespace exitance;

namespace {

Scene stripped(Scene scene) {
  for (Material& m : scene.materials) {
    m.base_color_texture.texture = m.emissive_texture.texture = -1;
    m.alpha_mode = Material::AlphaMode::Opaque;
  }
  scene.vertex_color.clear();
  scene.vertex_alpha.clear();
  return scene;
}

void run(const char* name, const Scene& scene, const TexelGBuffer& g, uint32_t spp) {
  const auto lighting = make_lighting_scene(scene);
  auto vk = VulkanIntegrator::create(lighting);
  IntegratorSettings settings;
  settings.spp = 1;
  vk->bake(g, settings);  // pipeline compilation
  settings.spp = spp;
  settings.seed = 1;
  const LightmapEstimate gpu = vk->bake(g, settings);
  settings.seed = 2;
  const LightmapEstimate cpu = CpuReferenceIntegrator(scene).bake(g, settings);
  double worst_z = 0, rel_mse = 0;
  const size_t n = g.texels.size(), group = 16;
  for (size_t begin = 0; begin < n; begin += group)
    for (int c = 0; c < 3; ++c) {
      double a = 0, b = 0, v = 0;
      for (size_t i = begin; i < std::min(n, begin + group); ++i)
        a += gpu.mean_total(i)[c], b += cpu.mean_total(i)[c], v += gpu.variance_of_mean(i)[c] + cpu.variance_of_mean(i)[c];
      if (v > 0) worst_z = std::max(worst_z, std::fabs(a - b) / std::sqrt(v));
    }
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const double a = gpu.mean_total(i)[c], b = cpu.mean_total(i)[c];
      rel_mse += (a - b) * (a - b) / (b * b + 1e-3);
    }
  rel_mse /= double(3 * n);
  std::printf("%-9s texels %zu spp %u | gpu %.2f s %.3f Mrays/s | cpu %.2f s %.3f Mrays/s | gpu/cpu time %.2f | worst |z| %.2f relMSE %.2e\n",
              name, n, spp, gpu.seconds, double(gpu.rays) / gpu.seconds * 1e-6, cpu.seconds,
              double(cpu.rays) / cpu.seconds * 1e-6, gpu.seconds / cpu.seconds, worst_z, rel_mse);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Vulkan vs CPU reference on a textured + masked + vertex-coloured scene"};
  uint32_t spp = 256;
  int grid = 32;
  app.add_option("--spp", spp, "samples per texel");
  app.add_option("--grid", grid, "texels per side on the floor and on the wall");
  CLI11_PARSE(app, argc, argv);
  const testing::TexturedScene t = testing::textured_masked_scene();
  TexelGBuffer g;
  for (int j = 0; j < grid; ++j)
    for (int i = 0; i < grid; ++i) {
      const float u = (float(i) + 0.5f) / float(grid), v = (float(j) + 0.5f) / float(grid);
      g.texels.push_back(testing::texel_at({-0.95f + 1.9f * u, 0, -0.95f + 1.9f * v}, {0, 1, 0}));
      g.texels.push_back(testing::texel_at({-0.95f + 1.9f * u, 0.02f + 1.46f * v, -1}, {0, 0, 1}));
    }
  run("textured", t.scene, g, spp);
  run("constant", stripped(t.scene), g, spp);
  return 0;
}
