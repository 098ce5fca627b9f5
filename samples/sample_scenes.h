// The sample scenes generate_samples writes; each fills an empty SceneBuilder.
#pragma once

#include "scene_builder.h"

namespace exitance::samples {

// Closed Cornell-style room, lit only by an emissive ceiling panel.
void buildCornellRoom(SceneBuilder& scene);
// Open courtyard under a directional sun; the sky is given to `bake --sky`.
void buildCourtyard(SceneBuilder& scene);
// Multi-storey building of furnished rooms with many lights, over 200 000 triangles.
void buildBuilding(SceneBuilder& scene);

}  // namespace exitance::samples
