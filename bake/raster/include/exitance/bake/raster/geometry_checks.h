// Scene problems a baker should point out before spending rays on them: texels enclosed by
// geometry, texels on coplanar overlapping surfaces (z-fighting), punctual lights shut inside
// closed geometry, and emitters that can never be sampled.
#pragma once

#include "exitance/bake/raster/parallel_progress.h"
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct GeometryCheckReport {
  size_t enclosed_texels = 0;        // most hemisphere rays hit back faces
  size_t coplanar_texels = 0;        // another surface lies in the texel's plane
  std::vector<int> enclosed_lights;  // indices into Scene::lights
  size_t unsampled_emitters = 0;     // emissive triangles with zero area
  // Per live texel: 1 when every hemisphere ray ended on the back of an opaque single-sided surface
  // (sealed_texels.h's first test, so finding sealed texels does not trace those rays again).
  std::vector<uint8_t> closed_texels;
};

// `progress` (optional) hears the share of texels checked.
GeometryCheckReport check_scene_geometry(const Scene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
                                         const FractionDone& progress = {});

// One warning line per kind of problem found (empty when the scene is clean).
std::vector<std::string> describe_geometry_problems(const GeometryCheckReport& report, const Scene& scene,
                                                    const std::string& file);

}  // namespace exitance
