// The whole `bake` run as a function: import → layout → G-buffer → unocclude → lighting →
// assemble → bundle. The command-line front end (bake/command/main.cpp) only parses and prints.
#pragma once
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/command/backend_choice.h"
#include "exitance/bake/diagnostics.h"
#include "exitance/bake/import/gltf_import.h"
#include "exitance/runtime/cpu_reference_integrator.h"

namespace exitance {

struct BakeOptions {
  std::string input;
  std::string output;          // empty = SCENE.bake next to the input
  std::string sky;             // "R,G,B" or an equirectangular image path; empty = black
  BackendRequest backend;
  ImportOptions import;
  AtlasSettings atlas;
  IntegratorSettings lighting;
  bool bounce_layers = false;
  // Light probes (--probes): spacing in scene units, 0 = automatic; probes_enabled false = none.
  bool probes_enabled = true;
  float probe_spacing = 0;
  uint32_t probe_spp = 512;       // rays per probe (--probe-spp)
  float probe_sh_window = 0;      // Hanning deringing window width (--probe-dering), 0 = off
  // Sparse voxel octree with radiant exitance (svo.bin, radiance.vdb): --voxel-resolution.
  bool svo_enabled = true;
  uint32_t voxel_resolution = 0;  // power of two; 0 = automatic (leaves about 4 texels wide)
  // Stage reporting for the progress bar: (stage name, fraction done, rays so far).
  std::function<void(const std::string&, double, uint64_t)> progress;
};

// Returns the run report (the manifest's "stats" and what was written). Throws InputError for
// bad input and std::runtime_error for other failures; nothing is written in either case.
nlohmann::json run_bake(const BakeOptions& options, Diagnostics& diagnostics);

// Parses --sky: "R,G,B" (three finite non-negative numbers) or an image file. Throws InputError.
Sky parse_sky_option(const std::string& value);

}  // namespace exitance
