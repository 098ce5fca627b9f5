// Lighting time the sealed-texel skip saves, measured directly: after the offline stages of a bake,
// lights the sealed texels alone and the other texels alone on the CPU reference, --repeat times
// interleaved, and prints the median seconds of each, the rays, and the seconds of finding the
// sealed texels. On a shared machine this is steadier than comparing two whole bakes, whose
// difference (under 1 % of the lighting) drowns in the load's noise.
//
//   bench_sealed_texel_time SCENE.gltf [--spp 128] [--texel-density D] [--repeat 3]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <vector>

#include "exitance/bake/command/bake_stages.h"
#include "exitance/bake/command/gbuffer_without_skipped.h"

#include "wall_clock.h"

using namespace exitance;
using exitance::bench::median;
using exitance::bench::seconds_since;

int main(int argc, char** argv) {
  BakeOptions options;
  uint32_t repeat = 3;
  options.lighting.spp = 128;
  options.backend.name = "cpu";
  CLI::App app{"lighting seconds of the sealed texels against the rest"};
  app.add_option("scene", options.input)->required();
  app.add_option("--spp", options.lighting.spp, "samples per texel");
  app.add_option("--texel-density", options.atlas.texel_density, "texels per scene unit (default: automatic)");
  app.add_option("--repeat", repeat, "runs of each to take the median of")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  try {
    Diagnostics diagnostics;
    std::vector<MeshWithoutLightmapUvs> without_lightmap_uvs;
    Scene imported = import_stage(options, diagnostics, without_lightmap_uvs);
    uv_generation_stage(imported, without_lightmap_uvs, options, diagnostics);
    const AtlasLayout layout = layout_stage(imported, options, diagnostics);
    TexelGBuffer gbuffer = raster_stage(imported, layout, options, diagnostics);
    const SceneForLighting scene = build_lighting_scene_stage(std::move(imported), options);
    const auto backend = backend_stage(scene, options, diagnostics);
    unocclude_stage(scene, gbuffer, options);
    const GeometryCheckReport checks = scene_checks_stage(scene, gbuffer, options, diagnostics);
    const auto find_start = std::chrono::steady_clock::now();
    const SealedTexels sealed = sealed_texels_stage(scene, gbuffer, checks, options);
    const double find_seconds = seconds_since(find_start);

    std::vector<uint8_t> unsealed(sealed.sealed.size());
    for (size_t i = 0; i < unsealed.size(); ++i) unsealed[i] = sealed.sealed[i] ? 0 : 1;
    const TexelGBuffer sealed_only = gbuffer_without_skipped(gbuffer, unsealed);
    const TexelGBuffer traced_only = gbuffer_without_skipped(gbuffer, sealed.sealed);
    std::vector<double> sealed_seconds, traced_seconds;
    uint64_t sealed_rays = 0, traced_rays = 0;
    for (uint32_t r = 0; r < repeat; ++r) {
      auto start = std::chrono::steady_clock::now();
      sealed_rays = backend->bake(sealed_only, options.lighting).rays;
      sealed_seconds.push_back(seconds_since(start));
      start = std::chrono::steady_clock::now();
      traced_rays = backend->bake(traced_only, options.lighting).rays;
      traced_seconds.push_back(seconds_since(start));
    }
    const double s = median(sealed_seconds), t = median(traced_seconds);
    std::printf("%s: %zu live texels, %zu sealed (%zu candidates), %u spp, median of %u\n", options.input.c_str(),
                gbuffer.texels.size(), sealed.texels, sealed.candidates, options.lighting.spp, repeat);
    std::printf("finding the sealed texels (240 rays per candidate, light test): %.3f s\n", find_seconds);
    std::printf("lighting the sealed texels alone: %.3f s, %llu rays (%.3g us per texel)\n", s,
                (unsigned long long)sealed_rays, sealed.texels ? 1e6 * s / double(sealed.texels) : 0.0);
    std::printf("lighting the other texels alone:  %.3f s, %llu rays (%.3g us per texel)\n", t,
                (unsigned long long)traced_rays, traced_only.texels.empty() ? 0.0 : 1e6 * t / double(traced_only.texels.size()));
    std::printf("saved by the skip: %.2f %% of the lighting time (%.3f s), net of finding them: %.3f s\n",
                s + t > 0 ? 100.0 * s / (s + t) : 0.0, s, s - find_seconds);
  } catch (const std::exception& e) {
    std::cerr << "bench_sealed_texel_time: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
