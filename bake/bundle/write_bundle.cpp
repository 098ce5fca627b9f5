#include "exitance/bake/bundle/write_bundle.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <future>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/bake/bundle/bundle_preview.h"
#include "exitance/bake/bundle/radiance_vdb.h"
#include "exitance/runtime/bundle/seam_stage.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/bundle/bundle_directory.h"
#include "exitance/runtime/bundle/light_layer_pages.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/common/light_layers.h"

namespace exitance {

namespace fs = std::filesystem;

fs::path bundle_folder(const BakeOptions& options) {
  return options.output.empty() ? fs::path(options.input).replace_extension(".bake") : fs::path(options.output);
}

namespace {

// Writes dir/preview/ and rewrites dir/manifest.json with its "preview" block and
// stats.seconds.preview; returns the new stats.
std::string write_preview_into_manifest(const fs::path& dir, const std::vector<formats::LightmapImage>& pages,
                                        formats::BundleManifest manifest, const BakeResults& results,
                                        const BakeOptions& options) {
  options.announce_stage("preview");
  const auto start = std::chrono::steady_clock::now();
  manifest.preview = write_bundle_preview(dir, pages, options.preview_size, results.scene_file.get().skipped);
  nlohmann::json stats = nlohmann::json::parse(manifest.stats_json);
  stats["seconds"]["preview"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  manifest.stats_json = stats.dump();
  std::ofstream file(dir / "manifest.json", std::ios::trunc);
  file << formats::write_bundle_manifest(manifest);
  if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
  return manifest.stats_json;
}

}  // namespace

WrittenBundle write_bundle_stage(const BakeResults& results, const std::function<nlohmann::json()>& seconds,
                                 Diagnostics& diagnostics, const BakeOptions& options) {
  options.announce_stage("write");
  AssemblyOptions assembly;
  assembly.bounce_layers = options.bounce_layers;
  assembly.dilation_texels = std::max(2, options.atlas.padding * 2);
  // Each page is assembled, its seams stitched (runtime/include/exitance/runtime/bundle/seam_stage.h:
  // after the gutter dilation, which the stitching repeats; with --seams off only measured) and
  // written before the next, in one image whose arrays each page reuses: holding every page at
  // once was 4.9 GB of fresh memory on the open city, whose first touch was most of the assembly.
  // The preview draws its views from all the pages, so with --preview they are all kept.
  const LightmapPageAssembler assembler(
      results.gbuffer, results.lightmap, assembly,
      results.sealed && results.sealed_skipped ? results.sealed->sealed : std::vector<uint8_t>{});
  BundleSeamStage seams(results.scene, results.layout, assembly.dilation_texels, options.stitch_seams);
  std::vector<formats::LightmapImage> pages(assembler.page_count());  // the preview's, or each page's size and channels
  formats::LightmapImage streamed;
  auto page_image = [&](size_t p) -> formats::LightmapImage& {
    formats::LightmapImage& image = options.preview ? pages[p] : streamed;
    assembler.assemble(p, image);
    seams.page(p, image);
    if (!options.preview) {
      pages[p].width = image.width, pages[p].height = image.height;
      for (const auto& [name, data] : image.channels) pages[p].channels[name];
    }
    return image;
  };
  // Light layers (--light-layers; docs/bundle.md "Light layers"): the bake's layout is the one its
  // scene.bin gets when opened, layer for layer.
  std::vector<formats::LightmapImage> layer_pages;
  if (results.lightmap.light_layers > 0) {
    std::vector<uint32_t> same(size_t(results.lightmap.light_layers));
    for (size_t k = 0; k < same.size(); ++k) same[k] = uint32_t(k);
    layer_pages = assemble_light_layer_pages(results.gbuffer, results.lightmap, same);
  }
  std::string stats_json;
  const fs::path out = bundle_folder(options);
  write_bundle_atomically(out, [&](const fs::path& dir) {
    // The files other than the pages (scene.bin, probes, svo.bin, radiance.vdb: serial encoders and
    // plain writes, 1-4 s at 10 M texels) on a thread of their own while the pages are compressed:
    // a page's compression has OpenEXR's workers but its line copies and file writes do not.
    // scene.bin's bytes and the octree's exitance may still be in the making (BakeResults says why).
    // Each file has one writer; if the pages throw, the future's destructor waits for the others
    // before the staging folder is removed.
    std::future<void> others = std::async(std::launch::async, [&] {
      if (results.probes) formats::write_probes_file((dir / "probes.bin").string(), results.probes->grid);
      const PersistedSceneFile& scene_file = results.scene_file.get();
      if (!scene_file.bytes.empty()) {
        std::ofstream scene_out(dir / "scene.bin", std::ios::binary);
        scene_out.write(reinterpret_cast<const char*>(scene_file.bytes.data()),
                        std::streamsize(scene_file.bytes.size()));
        if (!scene_out) throw std::runtime_error("cannot write " + (dir / "scene.bin").string());
      }
      if (results.voxels) {
        if (results.exitance.valid()) results.exitance.get();
        formats::write_svo_file((dir / "svo.bin").string(), results.voxels->svo);
        write_radiance_vdb((dir / "radiance.vdb").string(), results.voxels->svo);
      }
    });
    for (size_t p = 0; p < pages.size(); ++p) {
      formats::write_lightmap_exr((dir / ("lightmap-" + std::to_string(p) + ".exr")).string(), page_image(p));
      if (options.progress) options.progress("write", double(p + 1) / double(pages.size() + 1), 0);  // the rest: the last file
    }
    // What ran beside the pages is done (or has thrown) before the manifest records it.
    const PersistedSceneFile& scene_file = results.scene_file.get();
    if (results.exitance.valid()) results.exitance.get();
    if (!scene_file.skipped.empty())
      diagnostics.warn(options.input + ": scene.bin not written (exitance-relight cannot re-light this bundle): " +
                       scene_file.skipped);
    if (options.preview && scene_file.bytes.empty())
      diagnostics.warn("--preview: no views, only the lightmap pages: the bundle has no scene.bin (" +
                       scene_file.skipped + ")");
    formats::BundleManifest manifest = build_bundle_manifest(
        results, pages, results.input_sha256, seconds(), diagnostics.warnings.size(), options);
    if (!layer_pages.empty()) {
      formats::LightLayersInfo& info = manifest.light_layers.emplace();
      info.count = uint32_t(results.lightmap.light_layers);
      info.punctual = punctual_light_layer_count(uint32_t(results.scene.lights.size()), kDefaultLightLayerLimit);
      for (size_t p = 0; p < layer_pages.size(); ++p) info.files.push_back("light-layers-" + std::to_string(p) + ".exr");
    }
    {
      nlohmann::json stats = nlohmann::json::parse(manifest.stats_json);
      stats["seams"] = seams.report();
      manifest.stats_json = stats.dump();
    }
    stats_json = manifest.stats_json;
    for (size_t p = 0; p < layer_pages.size(); ++p)
      formats::write_lightmap_exr((dir / manifest.light_layers->files[p]).string(), layer_pages[p]);
    others.get();
    std::ofstream file(dir / "manifest.json");
    file << formats::write_bundle_manifest(manifest);
    if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
    file.close();
    // The preview's views are drawn from the staged bundle, so it comes last and then the manifest
    // is written again listing it.
    if (options.preview) stats_json = write_preview_into_manifest(dir, pages, manifest, results, options);
  });
  return {out, pages.size(), nlohmann::json::parse(stats_json)};
}

}  // namespace exitance
