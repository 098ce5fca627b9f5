// What the per-bounce mode ran (BounceGatherStatistics) as JSON: the bake manifest's stats.bounces
// and exitance-relight's report write the same object (docs/bundle.md, docs/cli.md).
#pragma once
#include <nlohmann/json.hpp>

#include "exitance/runtime/core/estimates.h"

namespace exitance {

inline nlohmann::json bounce_statistics_json(const BounceGatherStatistics& b) {
  return {{"bounces", b.bounces},
          {"samples_per_layer", b.samples},
          {"gathers", b.gathers},
          {"texelless_hits", b.texelless_hits},
          {"ratio", b.ratio},
          {"tail_rms", b.tail_rms},
          {"noise_rms", b.noise_rms},
          {"tail_below_noise", b.tail_below_noise},
          {"tail_completed", b.tail_completed},
          {"seconds", {{"passes", b.seconds.passes}, {"caches", b.seconds.caches}, {"tail", b.seconds.tail},
                       {"assembly", b.seconds.assembly}}}};
}

}  // namespace exitance
