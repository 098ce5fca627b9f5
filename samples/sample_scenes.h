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
// A room lit only through the gap of a door left ajar (the "Veach ajar" case).
void buildAjarRoom(SceneBuilder& scene);
// Two rooms sharing a 5 mm wall, one lit, one dark: light-leak measurement.
void buildThinWalls(SceneBuilder& scene);
// Open city: 64 instanced office blocks (five meshes) with lit and dark windows on
// kerbed plots along streets, under a directional sun; the sky is given to `bake --sky`.
void buildOpenCity(SceneBuilder& scene);

}  // namespace exitance::samples
