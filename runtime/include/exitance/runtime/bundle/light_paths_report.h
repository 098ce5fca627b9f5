// How many light subpaths a run traced and the pool vertices they left (LightmapEstimate's
// light_subpaths, light_subpath_vertices) as JSON: the bake manifest's stats.light_paths (which adds
// per_sample) and exitance-relight's report write the same object (docs/bundle.md, docs/cli.md).
#pragma once
#include <nlohmann/json.hpp>

#include "exitance/runtime/core/estimates.h"

namespace exitance {

inline nlohmann::json light_paths_json(const LightmapEstimate& estimate) {
  return {{"subpaths", estimate.light_subpaths}, {"vertices", estimate.light_subpath_vertices}};
}

}  // namespace exitance
