// Where light subpaths start in a scene (common/light_subpaths.h, light_subpath_walk.h), for every
// backend's pool: emitters, punctual lights and the sky by power.
#pragma once
#include "exitance/common/light_subpaths.h"
#include "exitance/runtime/core/lighting_scene.h"

namespace exitance {

// Start probabilities by luminance power: emitters pi x their NEE power; point 4 pi I, spot
// 2 pi (1 - cos_outer) I, directional pi r^2 E (LightingScene::punctual_power); the sky pi r^2 x its
// luminance's integral over directions (r = scene_radius). count and scale are 0 (the pool sets them).
LightSubpathSampling light_subpath_start(const LightingScene& scene);

}  // namespace exitance
