// The whole `bake` run as a function: the stages of bake_stages.h in data-flow order (import →
// layout → raster → bvh → backend → unocclude → checks → voxelize → probe placement → lighting →
// exitance → probes → write), each timed. The command-line front end (bake/command/main.cpp) only
// parses and prints.
#pragma once
#include <nlohmann/json.hpp>

#include "exitance/bake/bake_options.h"
#include "exitance/bake/diagnostics.h"

namespace exitance {

// Returns the run report: the manifest's "stats" with "seconds" completed by the write stage, plus
// "output" (the bundle's absolute path) and "pages". Throws InputError for bad input and
// std::runtime_error for other failures; nothing is written in either case.
nlohmann::json run_bake(const BakeOptions& options, Diagnostics& diagnostics);

}  // namespace exitance
