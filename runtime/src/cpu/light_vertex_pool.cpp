// Light subpaths for the pool (light_vertex_pool.h): the shared walk (common/light_subpath_walk.h)
// with Embree's rays, blocks of subpaths on TBB's threads.
#include "light_vertex_pool.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "exitance/common/light_subpath_walk.h"
#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/embree_scene.h"

namespace exitance {
namespace {

struct PoolTracer {
  const LightingScene& scene;
  const EmbreeScene& embree;
  LightSubpathSampling start;
  Vec3 centre;  // of the bounding sphere, radius `radius`
  float radius;
  int max_depth;
  int rr_start;
  EmitterGuidingCache* emitter_guide;

  // One subpath (light_subpath_walk.h); its vertices appended to `out`.
  void trace(uint64_t path, uint64_t seed, uint32_t key, uint32_t sampler, std::vector<LightVertex>& out, uint64_t& rays) const {
    PathSampler rng = path_sampler(seed, kLightSubpathStreamBase + path, key, sampler);
    LightSubpathWalk w = light_subpath_begin(scene, start, centre, radius, scene.punctual_light_layers, rng);
    while (w.valid) {
      ++rays;
      const Hit hit = embree.intersect(w.origin, w.direction, INFINITY);
      if (!hit.found) return;
      SurfacePoint y;
      if (!light_subpath_surface(scene, w, hit.triangle, hit.b1, hit.b2, y)) return;  // single-sided back faces absorb
      // NEE's density of the start from the first hit: the eye's learned sampling there, if any.
      float nee = 0;
      if (w.depth == 1) {
        const EmitterGuide g =
            w.from == kSubpathFromSky
                ? emitter_guide_none()
                : EmitterGuidingCache::vertex_site(emitter_guide, y.position, y.shading_normal, EmitterGuidingCache::Learning::None).guide;
        nee = light_subpath_nee_density(scene, w, y, g);
      }
      LightVertex v;
      Vec3 albedo;
      if (!light_subpath_vertex(scene, w, hit.triangle, hit.distance, hit.b1, hit.b2, y, nee, v, albedo)) return;
      if (light_vertex_finite(v)) out.push_back(v);
      if (!light_subpath_continue(scene, w, v, y, albedo, max_depth, rr_start, rng)) return;
    }
  }
};

}  // namespace

LightVertexPool trace_light_vertex_pool(const LightingScene& scene, const EmbreeScene& embree, LightSubpathSampling start,
                                        uint64_t paths, uint64_t seed, uint32_t key, uint32_t sampler, int max_depth,
                                        int rr_start, EmitterGuidingCache* emitter_guide) {
  LightVertexPool pool;
  pool.max_depth = max_depth;
  if (paths == 0 || max_depth < 1 || !light_subpaths_start_anywhere(start)) return pool;
  const PoolTracer tracer{scene, embree, start, (scene.bounds_lo + scene.bounds_hi) * 0.5f, scene_radius(scene),
                          max_depth, rr_start, emitter_guide};
  // Blocks of paths in parallel, concatenated in path order.
  constexpr uint64_t kBlock = 256;
  const uint64_t blocks = (paths + kBlock - 1) / kBlock;
  std::vector<std::vector<LightVertex>> block_vertices(blocks);
  std::vector<uint64_t> block_rays(blocks, 0);
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, blocks), [&](const tbb::blocked_range<uint64_t>& range) {
    for (uint64_t b = range.begin(); b != range.end(); ++b)
      for (uint64_t p = b * kBlock; p < std::min(paths, (b + 1) * kBlock); ++p)
        tracer.trace(p, seed, key, sampler, block_vertices[b], block_rays[b]);
  });
  size_t total = 0;
  for (const auto& v : block_vertices) total += v.size();
  pool.vertices.reserve(total);
  for (uint64_t b = 0; b < blocks; ++b) {
    pool.vertices.insert(pool.vertices.end(), block_vertices[b].begin(), block_vertices[b].end());
    pool.rays += block_rays[b];
  }
  pool.paths = paths;
  pool.sampling = start;
  if (!pool.vertices.empty()) {
    // One connection per eye vertex: n_c = paths / vertices.
    pool.sampling.count = float(double(paths) / double(pool.vertices.size()));
    pool.sampling.scale = float(double(pool.vertices.size()) / double(paths));
  }
  return pool;
}

}  // namespace exitance
