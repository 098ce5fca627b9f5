// The manifest.json of the test bundles (test_bundle.h), as JSON so tests can edit it. Kept apart
// from test_bundle.h so only the tests that edit manifests compile nlohmann::json.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>

#include "test_bundle.h"

namespace exitance::test {

// The manifest DESIGN §4 describes, for the pieces given.
nlohmann::json make_manifest(const std::optional<formats::ProbeGrid>& probes,
                             const std::optional<formats::SparseVoxelOctree>& svo);

}  // namespace exitance::test
