// The per-bounce mode's layer estimator on the CPU backend (issue 10; seed 003 ch. 3-4); the host
// side (schedule, caches, tail, statistics) is the core's, shared with Vulkan (core/per_bounce_bake.h).
//
// Layers: B_0(x) is one sample of path.h's estimator cut at direct light (next-event estimation to
// emitters, punctual lights and the sky, plus the MIS-weighted emission or sky the continuation ray
// sees); B_{k+1}(x) is one cosine ray whose hit y contributes albedo(y) * B_k(y), B_k(y) read from
// the layer's dilated atlas pages at y's lightmap UV (bilinear, BounceLayerCache). A miss adds 0
// (the sky is in B_0), a single-sided back face 0 (it absorbs, as in path mode). Rays are not
// capped at a tracing range, so no far-field value is needed.
//
// A hit with no lit texel to read - the back of a double-sided surface (texels hold the front's
// irradiance), a triangle the raster left without texels, or a G-buffer without atlas rectangles -
// gets B_k(y) estimated on the fly instead: one direct-light sample at y for k = 0, else one more
// gather ray from y reading B_{k-1}. That keeps such hits unbiased (with a G-buffer without
// rectangles the mode degenerates into a path tracer split by bounce). The SVO's exitance is not
// available here (it is filled from the lightmap after the lighting stage). Such hits are counted
// (BounceGatherStatistics::texelless_hits).
#include "cpu_bounce_integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <memory>

#include "exitance/common/bounce_gather.h"
#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/core/per_bounce_bake.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/runtime/embree_scene.h"

namespace exitance {
namespace {

using Counters = BounceGatherCounts;

class BounceGather {
 public:
  // `emitter_guide`: emitter guiding's cache (null: the default next-event sampling) and which
  // samples learn (EmitterGuidingCache::learning of the sample's index).
  BounceGather(const LightingScene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
               const std::vector<BounceLayerCache>& caches, const IntegratorSettings& settings,
               EmitterGuidingCache* emitter_guide)
      : scene_(scene), embree_(embree), gbuffer_(gbuffer), caches_(caches), settings_(settings),
        emitter_guide_(emitter_guide) {}

  // One sample of B_0 at x: path.h's estimator stopped after the direct light. `back_face`: its
  // continuation ray met the back of a single-sided surface (x is inside or under geometry).
  Vec3 direct(SurfacePoint x, PathSampler& rng, Counters& c, bool& back_face,
              EmitterGuidingCache::Learning learning) const {
    back_face = false;
    const LightingScene& scene = scene_;
    const Vec3 origin = offset_ray_origin(x.position, x.geometric_normal, scene.extent);
    ShadowRay shadow[kShadowRaysPerVertex];
    const EmitterGuidingCache::Site site = EmitterGuidingCache::vertex_site(emitter_guide_, x.position, x.shading_normal, learning);
    EmitterLearning learned;
    next_event_estimation(scene, x, origin, Vec3(1.0f), guide_vertex_cosine(), site.guide, rng, shadow[0], shadow[1],
                          shadow[2], learned);
    bool arrived[kShadowRaysPerVertex];
    Vec3 sum = connect(shadow, origin, c, arrived);
    if (site.learns)
      emitter_guide_->learn_arrived(site, learned.patch_index, learned.value, arrived[0], learned.punctual_light,
                                    learned.punctual_value, arrived[1]);
    const DirectionSample d = sample_continuation(settings_.sampling_strategy, x, rng);
    if (!(d.pdf > 0)) return sum;
    ++c.rays;
    const Hit hit = embree_.intersect(origin, d.direction, INFINITY);
    if (!hit.found) return sum + escaped_radiance(scene, d.direction, d.pdf);
    back_face = !(dot(d.direction, triangle_geometric_normal(scene, hit.triangle)) < 0.0f) &&
                !material_double_sided(scene_material(scene, scene_triangle_material(scene, hit.triangle)));
    const PathLimits direct_only{0, settings_.russian_roulette_start, settings_.safety_bounce_cap};
    const HitResult h = shade_continuation_hit(scene, hit.triangle, hit.distance, hit.b1, hit.b2, d.direction, d.pdf,
                                               Vec3(1.0f), 0, direct_only, site.guide, rng);
    return sum + h.radiance;
  }

  // One sample of B_{layer+1} at x: a continuation ray, the hit's albedo times B_layer there.
  Vec3 gather(SurfacePoint x, int layer, PathSampler& rng, Counters& c, EmitterGuidingCache::Learning learning) const {
    const LightingScene& scene = scene_;
    const DirectionSample d = sample_continuation(settings_.sampling_strategy, x, rng);
    if (!(d.pdf > 0)) return {0, 0, 0};
    // cos / (pi pdf): 1 for cosine sampling; kept so another strategy stays unbiased.
    const float weight = max(dot(x.shading_normal, d.direction), 0.0f) * kInvPi / d.pdf;
    const Vec3 origin = offset_ray_origin(x.position, x.geometric_normal, scene.extent);
    ++c.rays;
    const Hit hit = embree_.intersect(origin, d.direction, INFINITY);
    if (!hit.found) return {0, 0, 0};
    ++c.gathers;
    const uint tri = hit.triangle;
    const Vec3 ng = triangle_geometric_normal(scene, tri);
    const bool front = dot(d.direction, ng) < 0.0f;
    if (!front && !material_double_sided(scene_material(scene, scene_triangle_material(scene, tri)))) {
      ++c.back_faces;
      return {0, 0, 0};
    }
    const Vec3 albedo = scene_albedo(scene, tri, hit.b1, hit.b2);
    if (!(max_component(albedo) > 0)) return {0, 0, 0};
    Vec3 b;
    const SurfacePoint y = surface_point_on_triangle(scene, tri, ng, hit.b1, hit.b2, front);
    if (layer == 0 && settings_.trace_first_bounce) {
      b = on_the_fly(y, layer, rng, c, learning);
    } else if (!front || !caches_[size_t(layer)].lookup(gbuffer_, instance_of(tri), lightmap_uv(tri, hit.b1, hit.b2),
                                                        y.position, ng, b)) {
      ++c.texelless;
      b = on_the_fly(y, layer, rng, c, learning);
    }
    return albedo * b * weight;
  }

 private:
  // B_layer at a surface point that has no texels: one sample, from the layer below.
  Vec3 on_the_fly(SurfacePoint y, int layer, PathSampler& rng, Counters& c, EmitterGuidingCache::Learning learning) const {
    bool back_face = false;
    return layer == 0 ? direct(y, rng, c, back_face, learning) : gather(y, layer - 1, rng, c, learning);
  }

  // `arrived`: whether each ray arrived (unoccluded).
  Vec3 connect(const ShadowRay (&rays)[kShadowRaysPerVertex], Vec3 origin, Counters& c,
               bool (&arrived)[kShadowRaysPerVertex]) const {
    Vec3 sum{0, 0, 0};
    for (uint k = 0; k < kShadowRaysPerVertex; ++k) {
      const ShadowRay& r = rays[k];
      arrived[k] = false;
      const float state = r.contribution_state.w;
      if (state == kShadowNone) continue;
      ++c.rays;
      if (state != kShadowTrace) continue;
      const Vec3 d{r.direction_length.x, r.direction_length.y, r.direction_length.z};
      if (!embree_.occluded(origin, d, r.direction_length.w)) {
        sum += Vec3{r.contribution_state.x, r.contribution_state.y, r.contribution_state.z};
        arrived[k] = true;
      }
    }
    return sum;
  }

  uint32_t instance_of(uint tri) const {
    const Scene* source = scene_.source.get();
    return source && tri < source->triangle_instance.size() ? source->triangle_instance[tri]
                                                             : std::numeric_limits<uint32_t>::max();
  }
  Vec2 lightmap_uv(uint tri, float b1, float b2) const {
    const Scene* source = scene_.source.get();
    if (!source || size_t(tri) * 3 + 2 >= source->lightmap_uv.size()) return {0, 0};
    const Vec2* uv = &source->lightmap_uv[size_t(tri) * 3];
    return uv[0] * (1 - b1 - b2) + uv[1] * b1 + uv[2] * b2;
  }

  const LightingScene& scene_;
  const EmbreeScene& embree_;
  const TexelGBuffer& gbuffer_;
  const std::vector<BounceLayerCache>& caches_;
  const IntegratorSettings& settings_;
  EmitterGuidingCache* emitter_guide_;
};

// Layer passes over texels in parallel (TBB), each texel's samples in order: deterministic sums.
// Emitter guiding (settings.emitter_guiding): one cache through all layers' passes, learning from
// the direct-light samples (B_0's, and B_1's traced ones at gather hits), folded before each pass;
// inactive, as in path mode, when after 64 samples of a layer no record gains enough
// (EmitterGuidingCache::end_pass).
class CpuBounceLayerEstimator final : public BounceLayerEstimator {
 public:
  CpuBounceLayerEstimator(const LightingScene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
                          const IntegratorSettings& settings)
      : scene_(scene), embree_(embree), gbuffer_(gbuffer), settings_(settings),
        emitter_guide_(EmitterGuidingCache::for_bake(scene, gbuffer, settings)) {}

  void estimate(const BounceLayerPass& pass, const std::vector<BounceLayerCache>& caches,
                const std::vector<uint64_t>&) override {
    // The previous pass's learning becomes this pass's front table.
    if (emitter_guide_ && learned_samples_ > 0) emitter_guide_->end_pass(learned_samples_);
    EmitterGuidingCache* emitter_guide = emitter_guide_ && emitter_guide_->active() ? emitter_guide_.get() : nullptr;
    learned_samples_ = std::max(learned_samples_, pass.first_sample + pass.samples);
    const BounceGather gather(scene_, embree_, gbuffer_, caches, settings_, emitter_guide);
    const size_t k = size_t(pass.layer);
    // Over [begin, end), or over the listed texels (a partial pass): position j is texel texel_at(j).
    const std::vector<uint32_t>* listed = pass.texels;
    const size_t positions = listed ? listed->size() : pass.end - pass.begin;
    auto texel_at = [&](size_t j) { return listed ? size_t((*listed)[j]) : pass.begin + j; };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, positions, 64), [&](const tbb::blocked_range<size_t>& range) {
      Counters& c = counters_per_thread_.local();
      for (size_t j = range.begin(); j != range.end(); ++j) {
        const size_t i = texel_at(j);
        const uint64_t rays_before = c.rays;
        const LiveTexel& texel = gbuffer_.texels[i];
        const SurfacePoint x{texel.position, texel.geometric_normal, texel.shading_normal};
        for (uint32_t s = pass.first_sample; s < pass.first_sample + pass.samples; ++s) {
          PathSampler rng = k == 0 ? path_sampler(settings_.seed, i, s, settings_.sampler)
                                   : path_sampler(settings_.seed, kBounceRngStreamBase * k + i, s, settings_.sampler);
          bool back_face = false;
          const EmitterGuidingCache::Learning learning =
              emitter_guide ? EmitterGuidingCache::learning(s) : EmitterGuidingCache::Learning::None;
          const Vec3 value =
              k == 0 ? gather.direct(x, rng, c, back_face, learning) : gather.gather(x, int(k) - 1, rng, c, learning);
          if (back_face) ++pass.back_faces[i];
          if (!is_finite(value)) {
            ++c.nonfinite;  // counted and reported; counts as 0 (an unbiased estimator never produces these)
            continue;
          }
          for (int ch = 0; ch < 3; ++ch) {
            pass.sum[i * 3 + size_t(ch)] += value[ch];
            pass.sum_squared[i * 3 + size_t(ch)] += double(value[ch]) * double(value[ch]);
          }
        }
        if (pass.texel_rays) pass.texel_rays[i] = c.rays - rays_before;
      }
    });
  }

  // What emitter guiding's cache held at the end (nothing when it was off), and settings'
  // inspect_emitter_guiding called with it.
  void report(LightmapEstimate::EmitterGuidingReport& out) const {
    if (!emitter_guide_) return;
    emitter_guide_->report(out);
    if (settings_.inspect_emitter_guiding) settings_.inspect_emitter_guiding(*emitter_guide_);
  }

  BounceGatherCounts counts() const override {
    Counters sum;
    counters_per_thread_.combine_each([&](const Counters& c) {
      sum.rays += c.rays, sum.gathers += c.gathers, sum.texelless += c.texelless;
      sum.back_faces += c.back_faces, sum.nonfinite += c.nonfinite;
    });
    return sum;
  }

 private:
  const LightingScene& scene_;
  const EmbreeScene& embree_;
  const TexelGBuffer& gbuffer_;
  const IntegratorSettings& settings_;
  mutable tbb::combinable<Counters> counters_per_thread_;
  std::unique_ptr<EmitterGuidingCache> emitter_guide_;
  uint32_t learned_samples_ = 0;  // the most samples per texel any layer's passes have taken so far
};

}  // namespace

LightmapEstimate bake_per_bounce(const LightingScene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
                                 const IntegratorSettings& settings) {
  CpuBounceLayerEstimator estimator(scene, embree, gbuffer, settings);
  LightmapEstimate estimate = bake_per_bounce(gbuffer, settings, estimator);
  estimator.report(estimate.emitter_guiding);
  return estimate;
}

}  // namespace exitance
