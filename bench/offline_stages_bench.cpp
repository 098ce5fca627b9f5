// Seconds of the offline stages that grow with the texel count (raster, unocclude, checks, sealed
// texels, scene_file), without the lighting, and a digest of what each produced, so two builds can
// be compared for speed and for identical results on one command (bench/results/open-city-cpu.md).
// Each stage runs --repeat times on a fresh copy of its input; the medians of its wall-clock and of
// its CPU seconds (user + system, all threads) are printed: on a shared machine the CPU seconds are
// the steadier measure of the work done.
//
//   bench_offline_stages SCENE.gltf [--texel-density D] [--repeat 3]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <vector>


#include "exitance/bake/command/bake_stages.h"

#include "wall_clock.h"

using namespace exitance;
using exitance::bench::cpu_seconds;
using exitance::bench::Digest;
using exitance::bench::median;
using exitance::bench::seconds_since;

namespace {

uint64_t texel_digest(const TexelGBuffer& gbuffer) {
  Digest d;
  for (const LiveTexel& t : gbuffer.texels) {
    d.add_value(t.position), d.add_value(t.geometric_normal), d.add_value(t.shading_normal), d.add_value(t.albedo);
    d.add_value(t.page), d.add_value(t.x), d.add_value(t.y), d.add_value(t.triangle), d.add_value(t.instance);
    d.add_value(t.world_texel_size);
  }
  for (const AtlasPage& p : gbuffer.pages) d.add(p.coverage.data(), p.coverage.size() * sizeof(float));
  return d.value;
}

struct Seconds {
  double wall = 0, cpu = 0;
};

template <class Run, class Setup>
Seconds median_seconds(uint32_t repeat, Run run, Setup setup) {
  std::vector<double> wall, cpu;
  for (uint32_t r = 0; r < repeat; ++r) {
    setup();  // not timed
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = cpu_seconds();
    run();
    wall.push_back(seconds_since(start));
    cpu.push_back(cpu_seconds() - cpu_start);
  }
  return {median(wall), median(cpu)};
}

template <class Run>
Seconds median_seconds(uint32_t repeat, Run run) {
  return median_seconds(repeat, run, [] {});
}

}  // namespace

int main(int argc, char** argv) {
  BakeOptions options;
  uint32_t repeat = 3;
  options.backend.name = "cpu";
  CLI::App app{"seconds and result digests of the offline stages that grow with the texel count"};
  app.add_option("scene", options.input)->required();
  app.add_option("--texel-density", options.atlas.texel_density, "texels per scene unit (default: automatic)");
  app.add_option("--repeat", repeat, "runs of each stage to take the median of")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  try {
    Diagnostics diagnostics;
    std::vector<MeshWithoutLightmapUvs> without_lightmap_uvs;
    Scene imported = import_stage(options, diagnostics, without_lightmap_uvs);
    uv_generation_stage(imported, without_lightmap_uvs, options, diagnostics);
    const AtlasLayout layout = layout_stage(imported, options, diagnostics);
    TexelGBuffer rasterized;
    const Seconds raster = median_seconds(repeat, [&] { rasterized = raster_stage(imported, layout, options, diagnostics); });
    const uint64_t raster_digest = texel_digest(rasterized);
    const SceneForLighting scene = build_lighting_scene_stage(std::move(imported), options);

    TexelGBuffer gbuffer;
    size_t moved = 0;
    const Seconds unocclude = median_seconds(
        repeat, [&] { moved = unocclude_stage(scene, gbuffer, options); }, [&] { gbuffer = rasterized; });
    GeometryCheckReport checks;
    const Seconds check_seconds = median_seconds(repeat, [&] { checks = scene_checks_stage(scene, gbuffer, options, diagnostics); });
    Digest closed;
    closed.add(checks.closed_texels.data(), checks.closed_texels.size());
    SealedTexels sealed;
    const Seconds sealed_seconds = median_seconds(repeat, [&] { sealed = sealed_texels_stage(scene, gbuffer, checks, options); });
    PersistedSceneFile file;
    const Seconds scene_file =
        median_seconds(repeat, [&] { file = scene_file_stage(scene, gbuffer, layout, nullptr); });
    Digest bytes;
    bytes.add(file.bytes.data(), file.bytes.size());

    std::printf("%s: %zu live texels, %zu pages, median of %u\n", options.input.c_str(), gbuffer.texels.size(),
                gbuffer.pages.size(), repeat);
    std::printf("stage          wall s    cpu s\n");
    std::printf("raster        %8.3f %8.3f  texels %016llx\n", raster.wall, raster.cpu, (unsigned long long)raster_digest);
    std::printf("unocclude     %8.3f %8.3f  moved %zu, texels %016llx\n", unocclude.wall, unocclude.cpu, moved,
                (unsigned long long)texel_digest(gbuffer));
    std::printf("checks        %8.3f %8.3f  enclosed %zu, coplanar %zu, closed %016llx\n", check_seconds.wall, check_seconds.cpu,
                checks.enclosed_texels, checks.coplanar_texels, (unsigned long long)closed.value);
    std::printf("sealed_texels %8.3f %8.3f  sealed %zu of %zu candidates\n", sealed_seconds.wall, sealed_seconds.cpu, sealed.texels, sealed.candidates);
    std::printf("scene_file    %8.3f %8.3f  %zu bytes %016llx\n", scene_file.wall, scene_file.cpu, file.bytes.size(), (unsigned long long)bytes.value);
  } catch (const std::exception& e) {
    std::cerr << "bench_offline_stages: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
