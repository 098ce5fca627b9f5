// The bundle stage (DESIGN §4): lightmap pages assembled from the texel estimates, the manifest
// built from every stage's results, and all files written into OUT at once (a failed or interrupted
// run leaves an earlier bundle untouched).
#pragma once
#include <cstddef>
#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

#include "exitance/bake/bake_options.h"
#include "exitance/bake/bundle/bundle_manifest.h"
#include "exitance/bake/diagnostics.h"

namespace exitance {

struct WrittenBundle {
  std::filesystem::path folder;  // OUT, as bundle_folder gives it
  size_t pages = 0;              // lightmap pages written
  nlohmann::json stats;          // the manifest's "stats"
};

// OUT: --out, or SCENE.bake next to the input.
std::filesystem::path bundle_folder(const BakeOptions& options);

// Writes manifest.json, lightmap-<page>.exr, and with their stages probes.bin, svo.bin and
// radiance.vdb. `seconds` (stats.seconds so far, asked once the work beside the write is done) and
// the warning count go into the manifest; a scene.bin the scene cannot have is warned of here.
// Throws std::runtime_error (nothing written) when a file cannot be written, and rethrows what the
// results' pending work (BakeResults::scene_file, exitance) threw.
WrittenBundle write_bundle_stage(const BakeResults& results, const std::function<nlohmann::json()>& seconds,
                                 Diagnostics& diagnostics, const BakeOptions& options);

}  // namespace exitance
