// Where light subpaths start in a scene (common/light_subpaths.h, light_subpath_walk.h), for every
// backend's pool: emitters, punctual lights and the sky by power.
#pragma once
#include <algorithm>
#include <climits>
#include <cstdint>

#include "exitance/common/light_subpaths.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"

namespace exitance {

// The deepest light-subpath vertex a bake keeps: the eye paths' bounce limit (or the safety cap).
inline int light_subpath_depth(const IntegratorSettings& s) {
  return std::min(s.max_bounces >= 0 ? s.max_bounces : INT_MAX, s.safety_bounce_cap - 1);
}

// The fewest subpaths in a pool, so small passes of small atlases do not share a handful of vertices.
constexpr uint64_t kFewestLightSubpathsPerPool = 256;

// Start probabilities by luminance power: emitters pi x their NEE power; point 4 pi I, spot
// 2 pi (1 - cos_outer) I, directional pi r^2 E (LightingScene::punctual_power); the sky pi r^2 x its
// luminance's integral over directions (r = scene_radius). count and scale are 0 (the pool sets them).
LightSubpathSampling light_subpath_start(const LightingScene& scene);

}  // namespace exitance
