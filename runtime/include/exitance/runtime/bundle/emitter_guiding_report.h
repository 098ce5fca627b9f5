// What emitter guiding's cache held at the end of a run (LightmapEstimate::EmitterGuidingReport) as
// JSON: the bake manifest's stats.emitter_guiding and exitance-relight's report write the same
// object (docs/bundle.md, docs/cli.md).
#pragma once
#include <nlohmann/json.hpp>

#include "exitance/runtime/core/estimates.h"

namespace exitance {

inline nlohmann::json emitter_guiding_json(const LightmapEstimate::EmitterGuidingReport& e) {
  return {{"records", e.records},
          {"records_sampling_learned", e.records_sampling_learned},
          {"patches", e.patches},
          {"punctual_lights", e.punctual_lights},
          {"memory_bytes", e.memory_bytes},
          {"dropped_after_learning", e.dropped},
          {"setup_seconds", e.setup_seconds},
          {"folds", e.folds},
          {"fold_seconds", e.fold_seconds}};
}

}  // namespace exitance
