// The CPU backend's pool of light-subpath vertices (common/light_subpaths.h): subpaths traced from the
// scene's emitters, punctual lights and sky by Embree, their vertices kept in path order so a pool
// is the same for a seed whatever the thread count.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/light_subpath_start.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/core/scene_access.h"

namespace exitance {

class EmbreeScene;
class EmitterGuidingCache;

struct LightVertexPool {
  std::vector<LightVertex> vertices;
  uint64_t paths = 0;
  uint64_t rays = 0;
  LightSubpathSampling sampling = light_subpaths_none();  // count and scale from this pool
  // The deepest vertex kept (connections need depth + eye bounce <= this).
  int max_depth = 0;
};

// `paths` light subpaths of sample `key` (each a stream of its own), vertices up to `max_depth`
// edges from the light (the eye's bounce limits), Russian roulette from depth rr_start.
// `emitter_guide`: the eye's learned next-event sampling (null: by power), whose density at the
// first hit weighs the subpaths against next-event estimation there.
LightVertexPool trace_light_vertex_pool(const LightingScene& scene, const EmbreeScene& embree, LightSubpathSampling start,
                                        uint64_t paths, uint64_t seed, uint32_t key, uint32_t sampler, int max_depth,
                                        int rr_start, EmitterGuidingCache* emitter_guide = nullptr);

}  // namespace exitance
