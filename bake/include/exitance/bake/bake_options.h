// The options of one `bake` run, as the command line gives them (docs/cli.md): every stage's
// settings in one place. The stages read their part of it; bundle/ records it in the manifest.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/runtime/core/integrator_settings.h"

namespace exitance {

struct BackendRequest {
  std::string name = "auto";  // auto | vulkan | cpu
  int device_index = -1;      // --device N; -1 = prefer a discrete GPU
  bool validation = false;    // EXITANCE_VULKAN_VALIDATION=1: validation layers, any message is an error
};

// --adaptive: auto = adaptive sampling where it is implemented and a budget leaves room for it
// (CPU backend, path mode, with --time or --target-error); on = always (the CPU backend); off = never.
enum class AdaptiveRequest : uint8_t { Auto, On, Off };

struct BakeOptions {
  std::string input;
  std::string output;          // empty = SCENE.bake next to the input
  std::string sky;             // "R,G,B" or an equirectangular image path; empty = black
  std::string write_gltf;      // --write-gltf: the scene with its generated lightmap UVs; empty = none
  BackendRequest backend;
  ImportOptions import;
  AtlasSettings atlas;
  IntegratorSettings lighting;  // lighting.adaptive is decided by the lighting stage from adaptive_request
  AdaptiveRequest adaptive_request = AdaptiveRequest::Auto;
  // --integrator auto (the bake command's default): lighting.integrator is decided once the backend is
  // chosen (bake/command/automatic_integrator.h); false: lighting.integrator as given.
  bool integrator_auto = false;
  // --emitter-guiding auto (the bake command's default): lighting.emitter_guiding is decided with the
  // integrator (on where the CPU backend path traces in one process); false: as given.
  bool emitter_guiding_auto = false;
  // --guiding auto given on the command line (not the default): the Vulkan backend then runs the
  // measured choice too; by default it stays unguided (bake/command/automatic_integrator.h).
  bool guiding_auto_given = false;
  bool bounce_layers = false;
  // Sealed texels (bake/raster/sealed_texels.h) are found either way; true: the lighting stage
  // does not trace them (they are dilated from lit neighbours). --no-skip: false.
  bool skip_sealed_texels = true;
  // Light probes (--probes): spacing in scene units, 0 = automatic; probes_enabled false = none.
  bool probes_enabled = true;
  float probe_spacing = 0;
  uint32_t probe_spp = 512;       // rays per probe (--probe-spp)
  float probe_sh_window = 0;      // Hanning deringing window width (--probe-dering), 0 = off
  // Sparse voxel octree with radiant exitance (svo.bin, radiance.vdb): --voxel-resolution.
  bool svo_enabled = true;
  uint32_t voxel_resolution = 0;  // power of two; 0 = automatic (leaves about 4 texels wide)
  // --preview: PNGs of the pages and default views in OUT/preview/ (bake/bundle/bundle_preview.h),
  // views preview_size pixels wide.
  bool preview = false;
  // --seams stitch|off: least-squares seam stitching of the lightmap pages (runtime/src/bundle/seam_*.cpp).
  bool stitch_seams = true;
  // --denoise [--denoise-radius R]: the texture-space filter of the indirect light after the
  // lighting stage (runtime/bundle/indirect_denoise.h); biased, so off by default.
  bool denoise = false;
  int denoise_radius = 3;
  uint32_t preview_size = 512;
  // The bundle cache (bake/cache/bundle_cache.h): a folder, or empty for none. Empty by default
  // here; the bake command defaults to .exitance-cache beside OUT (--cache DIR, --no-cache).
  // Not part of the cache key: where results are kept does not change them.
  std::string cache_directory;
  // Stage reporting for the progress bar: (stage name, fraction done, rays so far).
  std::function<void(const std::string&, double, uint64_t)> progress;

  // Tells the progress bar that `stage` starts.
  void announce_stage(const std::string& stage) const {
    if (progress) progress(stage, 0, 0);
  }
};

}  // namespace exitance
