// Seconds of exitance-relight's host stages, without the device: what RefreshSession::open does on
// the host (manifest, scene.bin read and restore, svo.bin, the lighting scene, the texel grid, the
// baked lightmap) and what write_refreshed_bundle does after the lighting (voxel exitance, page
// assembly, seams, EXR pages, svo.bin, scene.bin encoding and writing), each timed alone on a
// bundle, with a digest of what each produced so two builds can be compared for speed and for
// identical results (bench/results/host-stages.md). The lightmap estimate written is synthetic
// (deterministic per texel: the device is not used), at 256 samples per texel.
//
//   bench_host_stages BUNDLE [--out DIR] [--repeat 3]
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/scene_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/bundle/seam_stage.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/refresh/baked_lightmap.h"
#include "exitance/runtime/refresh/texel_grid.h"
#include "exitance/runtime/scene_file_conversion.h"

#include "wall_clock.h"

using namespace exitance;
using exitance::bench::cpu_seconds;
using exitance::bench::Digest;
using exitance::bench::median;
using exitance::bench::seconds_since;
namespace fs = std::filesystem;

namespace {

uint64_t file_digest(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Digest d;
  d.add(bytes.data(), bytes.size());
  return d.value;
}

uint64_t pixel_digest(const formats::LightmapImage& image) {
  Digest d;
  d.add(&image.width, sizeof image.width), d.add(&image.height, sizeof image.height);
  for (const auto& [name, data] : image.channels) d.add(name.data(), name.size()), d.add(data.data(), data.size() * sizeof(float));
  return d.value;
}

// A deterministic estimate over `texels` live texels: 256 samples each, values from a hash of the index.
LightmapEstimate synthetic_estimate(size_t texels) {
  LightmapEstimate e;
  e.texels.resize(texels);
  for (size_t i = 0; i < texels; ++i) {
    uint32_t h = uint32_t(i) * 2654435761u;
    TexelAccumulator& t = e.texels[i];
    t.samples = 256;
    for (int c = 0; c < 3; ++c) {
      h ^= h >> 15, h *= 2246822519u, h ^= h >> 13;
      const double mean = double(h % 10000) / 10000.0 + 0.01 * c;
      t.total[c] = mean * t.samples;
      t.total_squared[c] = (mean * mean + 0.01) * t.samples;
      t.direct[c] = 0.5 * t.total[c];
    }
  }
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Seconds of exitance-relight's host stages on a bundle (no device)"};
  std::string bundle, out = "/tmp/host_stages_bench.bake";
  uint32_t repeat = 3;
  app.add_option("bundle", bundle)->required();
  app.add_option("--out", out, "folder the stages write into (replaced)");
  app.add_option("--repeat", repeat, "runs per stage; the median is printed")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  struct Row {
    std::string stage;
    double wall, cpu;
    std::string digest;
  };
  std::vector<Row> rows;
  auto time = [&](const std::string& stage, auto run, auto digest) {
    std::vector<double> wall, cpu;
    for (uint32_t r = 0; r < repeat; ++r) {
      const auto start = std::chrono::steady_clock::now();
      const double cpu_start = cpu_seconds();
      run();
      wall.push_back(seconds_since(start));
      cpu.push_back(cpu_seconds() - cpu_start);
    }
    char hex[32];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(digest()));
    rows.push_back({stage, median(wall), median(cpu), hex});
  };

  const fs::path in(bundle);
  std::ifstream manifest_in(in / "manifest.json", std::ios::binary);
  const std::string manifest_text((std::istreambuf_iterator<char>(manifest_in)), std::istreambuf_iterator<char>());
  formats::BundleManifest manifest;
  time("load: manifest", [&] { manifest = formats::parse_bundle_manifest(manifest_text, bundle); },
       [&] { return uint64_t(manifest.pages.size()); });
  std::optional<formats::SceneFile> scene_file;
  time("load: scene.bin read", [&] { scene_file = formats::read_scene_file((in / manifest.scene->file).string()); },
       [&] { return file_digest(in / manifest.scene->file); });
  PersistedScene persisted;
  time("load: scene restore", [&] { persisted = restore_scene(*scene_file); },
       [&] { return uint64_t(persisted.gbuffer.texels.size()); });
  std::optional<formats::SparseVoxelOctree> svo;
  if (manifest.svo)
    time("load: svo.bin read", [&] { svo = formats::read_svo_file((in / manifest.svo->file).string()); },
         [&] { return uint64_t(svo->nodes.size()); });
  std::optional<LightingScene> lighting;
  const std::shared_ptr<const Scene> scene(std::shared_ptr<const Scene>{}, &persisted.scene);
  time("load: lighting scene (BVH4)", [&] { lighting.emplace(build_lighting_scene(scene, to_bvh4(persisted.bvh))); },
       [] { return uint64_t(0); });
  std::optional<TexelGrid> grid;
  time("load: texel grid", [&] { grid.emplace(persisted.gbuffer); }, [&] { return uint64_t(grid->texel_count()); });
  const formats::BakeSettings baked = manifest.settings.value_or(formats::BakeSettings{});
  std::optional<LightmapEstimate> baked_lightmap;
  time("load: baked lightmap", [&] { baked_lightmap = read_baked_lightmap(bundle, manifest, persisted.gbuffer, 1); },
       [&] { return uint64_t(baked_lightmap ? baked_lightmap->texels.size() : 0); });

  const LightmapEstimate estimate = synthetic_estimate(persisted.gbuffer.texels.size());
  if (svo) {
    formats::SparseVoxelOctree filled;
    time("write: voxel exitance", [&] { filled = *svo, fill_svo_exitance(filled, persisted.scene, persisted.gbuffer, estimate); },
         [&] {
           const std::vector<uint8_t> bytes = formats::encode_svo(filled);
           Digest d;
           d.add(bytes.data(), bytes.size());
           return d.value;
         });
    svo = filled;
  }
  AssemblyOptions assembly;
  assembly.bounce_layers = manifest.has_bounce_layers();
  assembly.dilation_texels = std::max(2, int(baked.padding) * 2);
  std::vector<formats::LightmapImage> pages;
  time("write: page assembly", [&] { pages = assemble_lightmap_pages(persisted.gbuffer, estimate, assembly); },
       [&] {
         Digest d;
         for (const auto& p : pages) d.value ^= pixel_digest(p);
         return d.value;
       });
  const std::vector<formats::LightmapImage> assembled = pages;
  time("write: seams", [&] {
         pages = assembled;
         stitch_bundle_seams(pages, persisted.scene, persisted.atlas, assembly.dilation_texels, bundle_stitches_seams(manifest.stats_json));
       },
       [&] {
         Digest d;
         for (const auto& p : pages) d.value ^= pixel_digest(p);
         return d.value;
       });
  fs::remove_all(out);
  fs::create_directories(out);
  const fs::path dir(out);
  for (size_t p = 0; p < pages.size(); ++p) {
    const fs::path file = dir / ("lightmap-" + std::to_string(p) + ".exr");
    time("write: " + file.filename().string() + " (" + std::to_string(pages[p].width) + "x" + std::to_string(pages[p].height) + ", " +
             std::to_string(pages[p].channels.size()) + " channels)",
         [&] { formats::write_lightmap_exr(file.string(), pages[p]); },
         [&] { return file_digest(file); });
    time("  read back " + file.filename().string(), [&] { (void)formats::read_lightmap_exr(file.string()); },
         [&] { return pixel_digest(formats::read_lightmap_exr(file.string())); });
  }
  if (persisted.has_probe_grid())
    time("write: probes.bin", [&] { formats::write_probes_file((dir / "probes.bin").string(), persisted.probes); },
         [&] { return file_digest(dir / "probes.bin"); });
  if (svo)
    time("write: svo.bin", [&] { formats::write_svo_file((dir / "svo.bin").string(), *svo); }, [&] { return file_digest(dir / "svo.bin"); });
  std::vector<uint8_t> scene_bytes;
  time("write: scene.bin encode", [&] { scene_bytes = formats::encode_scene(*scene_file); }, [&] {
    Digest d;
    d.add(scene_bytes.data(), scene_bytes.size());
    return d.value;
  });
  time("write: scene.bin file", [&] {
         std::ofstream f(dir / "scene.bin", std::ios::binary);
         f.write(reinterpret_cast<const char*>(scene_bytes.data()), std::streamsize(scene_bytes.size()));
       },
       [&] { return uint64_t(scene_bytes.size()); });

  std::printf("%s: %zu live texels, %zu pages, probes %s, svo %s; medians of %u runs, %u hardware threads\n", bundle.c_str(),
              persisted.gbuffer.texels.size(), pages.size(), persisted.has_probe_grid() ? "yes" : "no", svo ? "yes" : "no", repeat,
              std::thread::hardware_concurrency());
  std::printf("| stage | wall s | cpu s | digest |\n|---|---|---|---|\n");
  double load = 0, write = 0;
  for (const Row& r : rows) {
    std::printf("| %s | %.3f | %.3f | %s |\n", r.stage.c_str(), r.wall, r.cpu, r.digest.c_str());
    if (r.stage.rfind("load:", 0) == 0) load += r.wall;
    if (r.stage.rfind("write:", 0) == 0) write += r.wall;
  }
  std::printf("| **load (sum)** | %.3f | | |\n| **write (sum)** | %.3f | | |\n", load, write);
  return 0;
}
