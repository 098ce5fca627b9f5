// The CPU reference: path.h's estimator with every ray traced at once by Embree, one sample after
// another per texel or probe, in parallel over texels with TBB.
#include "exitance/runtime/cpu_reference_integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "cpu_bounce_integrator.h"
#include "exitance/runtime/core/adaptive_sampling_plan.h"
#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/core/grid_guiding_cache.h"
#include "exitance/runtime/core/guide_grid_locator.h"
#include "exitance/runtime/core/guiding_choice.h"
#include "exitance/runtime/core/pass_scheduler.h"
#include "exitance/runtime/core/svo_guiding_fields.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/common/guide_learning.h"  // after scene_access.h: path.h reads its accessors
#include "exitance/common/light_layers.h"
#include "exitance/runtime/core/work_share.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/common/light_subpath_walk.h"
#include "light_vertex_pool.h"

namespace exitance {
namespace {

constexpr int kMaxRecordedBounces = 16;
// Grid guiding learns during the first samples per texel and then samples its frozen table: on
// small scenes the learning (a target per ray, atomic adds) costs as much as the ray itself, and by
// then the table has stopped improving (bench/results/guiding.md). Shared with the Vulkan backend.
constexpr uint32_t kGuidingLearningSamples = GridGuidingCache::kLearningSamples;
// Light subpaths traced into one pool at most (~4 vertices and 320 bytes each on indoor scenes):
// larger passes trace a pool per chunk of their samples.
constexpr uint64_t kMostLightSubpathsPerPool = uint64_t(1) << 17;
// Subpaths in a pool that serves `samples` texel or probe samples, `per_sample` each, within the bounds.
uint64_t light_subpaths_for(double samples, double per_sample) {
  return uint64_t(std::clamp(std::ceil(samples * per_sample), double(kFewestLightSubpathsPerPool), double(kMostLightSubpathsPerPool)));
}
// Samples per pool in passes over `items` texels or probes: the most that keep a pool within its bound.
uint32_t samples_per_pool(double items, double per_sample) {
  return uint32_t(std::max(1.0, std::floor(double(kMostLightSubpathsPerPool) / std::max(1.0, items * per_sample))));
}
// A target error plans at most this many samples for a texel without --spp (documented).
constexpr uint32_t kMostSamplesForTarget = 1u << 17;

// Per-sample contributions to E/pi, split by the number of diffuse reflections between the
// light and the texel (0 = direct).
struct PathContributions {
  Vec3 by_bounce[kMaxRecordedBounces + 1];  // the last slot gathers every deeper bounce
  int recorded = 0;
  void add(int bounce, Vec3 value) { by_bounce[std::min(bounce, recorded)] += value; }
  Vec3 total() const {
    Vec3 sum{0, 0, 0};
    for (int k = 0; k <= recorded; ++k) sum += by_bounce[k];
    return sum;
  }
  // Directional texels (DirectionalMode::Sh1): the L1 estimate of the texel's next-event samples,
  // their E/pi, and the first continuation's sh1_direction_factor, which every other contribution shares.
  bool directional = false;
  Vec3 texel_nee_sh1[3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  Vec3 texel_nee{0, 0, 0};
  Vec3 first_factor{0, 0, 0};
  // The path's L1 coefficient along `axis` (RGB).
  Vec3 sh1(int axis) const { return texel_nee_sh1[axis] + (total() - texel_nee) * first_factor[axis]; }
  // Light layers (light_layers.h; IntegratorSettings::light_layers): per layer the path's E/pi from
  // that light, attributed as the Vulkan wavefront does (path.glsl, shade.comp); null: not kept.
  Vec3* by_light = nullptr;
  void add_light(uint32_t layer, Vec3 value) {
    if (by_light) by_light[layer] += value;
  }
};

// After a pass split over ranks: every rank's texels' sums (and their rays, the next split's cost)
// onto every rank, so each holds the whole estimate and any texel can continue anywhere.
void gather_texel_sums(WorkShare& share, LightmapEstimate& estimate, const std::vector<size_t>& bounds,
                       std::vector<uint64_t>& texel_rays) {
  const size_t n = estimate.texels.size();
  allgather_items(share, estimate.texels.data(), 1, bounds);
  for (int k = 0; k < estimate.recorded_bounces; ++k) allgather_items(share, estimate.bounces.data() + size_t(k) * n * 3, 3, bounds);
  if (!estimate.sh1.empty()) allgather_items(share, estimate.sh1.data(), 9, bounds);
  allgather_items(share, texel_rays.data(), 1, bounds);
}

// Emitter guiding at a path's vertices (null: the default next-event sampling); which of its
// next-event samples teach the back tables (EmitterGuidingCache::learning). Outside Impl: a default
// argument of an Impl member cannot use a nested class's member initializers (clang).
struct EmitterGuiding {
  EmitterGuidingCache* cache = nullptr;
  EmitterGuidingCache::Learning learning = EmitterGuidingCache::Learning::None;
};

}  // namespace

struct CpuReferenceIntegrator::Impl {
  std::shared_ptr<const LightingScene> lighting;
  std::shared_ptr<const EmbreeScene> embree;

  const LightingScene& scene() const { return *lighting; }

  // Traces the shadow rays of one vertex; returns what the unoccluded ones carry. With `sh1` (a
  // directional texel's own vertex), also adds their L1 estimates there.
  // `arrived`: whether each ray arrived (unoccluded).
  // `each`: what each ray carries (0 where it was occluded or not traced).
  Vec3 connect(const ShadowRay (&rays)[3], Vec3 origin, uint64_t& traced, const SurfacePoint& x,
               Vec3* sh1 = nullptr, bool (*arrived)[3] = nullptr, Vec3 (*each)[3] = nullptr) const {
    Vec3 sum{0, 0, 0};
    if (arrived) (*arrived)[0] = (*arrived)[1] = (*arrived)[2] = false;
    if (each) (*each)[0] = (*each)[1] = (*each)[2] = Vec3{0, 0, 0};
    for (const ShadowRay& r : rays) {
      const float state = r.contribution_state.w;
      if (state == kShadowNone) continue;
      ++traced;
      if (state != kShadowTrace) continue;
      const Vec3 d{r.direction_length.x, r.direction_length.y, r.direction_length.z};
      if (!embree->occluded(origin, d, r.direction_length.w)) {
        const Vec3 c{r.contribution_state.x, r.contribution_state.y, r.contribution_state.z};
        if (arrived) (*arrived)[&r - rays] = true;
        if (each) (*each)[&r - rays] = c;
        sum += c;
        if (sh1) {
          const Vec3 f = sh1_direction_factor(x, d);
          for (int axis = 0; axis < 3; ++axis) sh1[axis] += c * f[axis];
        }
      }
    }
    return sum;
  }

  // The light layer of an emissive triangle: its material's (emission.w, lay_out_light_layers).
  uint32_t emitter_light_layer(uint32_t triangle) const {
    const LightingScene& s = scene();
    return uint32_t(s.materials[floatBitsToUint(s.triangles[triangle].p0_material.w)].emission.w);
  }

  // What a guided vertex's continuation ray saw, as the learning target of its bin (luminance of
  // incident radiance): the emission and albedo x the frozen table's cosine-weighted mean at the hit
  // (common/guide_learning.h, shared with the Vulkan wavefront).
  float learning_target(const GridGuidingCache& guide, const Hit& hit, Vec3 wi) const {
    const LightingScene& s = scene();
    if (!hit.found) return guide_learning_target(guide_learning_escape(s, wi), 0.0f);
    const GuideLearningHit h = guide_learning_hit(s, hit.triangle, hit.b1, hit.b2, wi);
    const float expected = h.reads_expectation ? guide.expected_cosine_radiance(guide.record_of(h.y.position, h.y.shading_normal)) : 0.0f;
    return guide_learning_target(h, expected);
  }

  // What trace() asks of a guide: the record of a vertex (site), its strategy (vertex), and what a
  // continuation ray teaches it (observe). No guide: cosine sampling, exactly as before guiding.
  struct NoGuide {
    uint32_t site(const SurfacePoint&, int) const { return 0; }
    GuideVertex vertex(uint32_t) const { return guide_vertex_cosine(); }
    void observe(uint32_t, const GuideVertex&, Vec3, const Hit&) const {}
  };
  // Grid guiding: vertices sample the frozen table's mixture; while learning, every ray teaches the back table.
  struct GridGuide {
    const Impl& impl;
    GridGuidingCache& cache;
    bool learn;
    uint32_t site(const SurfacePoint& x, int) const { return cache.record_of(x.position, x.shading_normal); }
    GuideVertex vertex(uint32_t record) const { return cache.vertex(record); }
    void observe(uint32_t record, const GuideVertex& g, Vec3 direction, const Hit& hit) const {
      if (!learn || record == GridGuidingCache::kNoRecord) return;
      const Vec3 local = guide_to_class_local(g.normal_class, direction);
      if (local.z > 0) cache.learn(record, guide_bin_of_local(local), impl.learning_target(cache, hit, direction));
    }
  };
  // SVO guiding: vertices sample their bin's field and are counted for the next rebuild's bins;
  // without `texels`, the texel's own vertex samples cosine (its Sobol pair stays stratified).
  struct SvoGuide {
    SvoGuidingFields& fields;
    bool counting;
    bool texels;
    uint32_t site(const SurfacePoint& x, int bounce) const {
      const uint32_t node = fields.node_of(x.position);
      if (counting) fields.count(node, x.shading_normal);
      return bounce == 0 && !texels ? SvoGuidingFields::kNoRecord : fields.record_of(node, x.shading_normal);
    }
    GuideVertex vertex(uint32_t record) const { return fields.vertex(record); }
    void observe(uint32_t, const GuideVertex&, Vec3, const Hit&) const {}
  };

  // Light subpaths (light_subpaths.h): eye vertex x (bounce `bounce`, its light-subpath state `eye`)
  // connects to one pool vertex picked uniformly (light_subpath_walk.h light_subpath_connection); the
  // connection's E/pi goes to bounce + the vertex's depth, and to its light's layer.
  void connect_to_pool(const LightVertexPool& pool, const SurfacePoint& x, Vec3 origin, Vec3 throughput,
                       const GuideVertex& g, int bounce, const EyeSubpathVertex& eye, bool directional_texel,
                       PathSampler& rng, PathContributions& out, uint64_t& rays) const {
    const float u = sample_1d(rng);
    const size_t count = pool.vertices.size();
    const LightVertex& y = pool.vertices[std::min(size_t(double(u) * double(count)), count - 1)];
    const ShadowRay ray = light_subpath_connection(scene(), pool.sampling, y, x, origin, throughput, g, bounce, eye, pool.max_depth);
    if (ray.contribution_state.w != kShadowTrace) return;
    ++rays;
    const Vec3 direction{ray.direction_length.x, ray.direction_length.y, ray.direction_length.z};
    if (embree->occluded(origin, direction, ray.direction_length.w)) return;
    const Vec3 c{ray.contribution_state.x, ray.contribution_state.y, ray.contribution_state.z};
    out.add(bounce + int(floatBitsToUint(y.position_depth.w)), c);
    out.add_light(floatBitsToUint(y.geometric_normal_layer.w), c);
    if (directional_texel) {
      const Vec3 to_light = Vec3{y.position_depth.x, y.position_depth.y, y.position_depth.z} - x.position;
      const Vec3 f = sh1_direction_factor(x, to_light / std::sqrt(dot(to_light, to_light)));
      for (int axis = 0; axis < 3; ++axis) out.texel_nee_sh1[axis] += c * f[axis];
      out.texel_nee += c;
    }
  }

  // One path sample of E/pi at x; `first_bounce` is the bounce x stands for (0 at a texel).
  // `pool`: light subpaths to connect to (null or empty: the path tracer alone).
  template <class Guide>
  void trace(SurfacePoint x, const IntegratorSettings& settings, PathSampler& rng, PathContributions& out,
             uint64_t& rays, const Guide& guide, uint64_t* guided_vertices = nullptr,
             EmitterGuiding emitter_guiding = {}, const LightVertexPool* pool = nullptr) const {
    const LightingScene& s = scene();
    const PathLimits limits{settings.max_bounces, settings.russian_roulette_start, settings.safety_bounce_cap};
    Vec3 throughput{1, 1, 1};
    const bool subpaths = pool && pool->sampling.count > 0;
    EyeSubpathVertex eye = eye_subpath_vertex_none();
    if (subpaths) eye.sampling = pool->sampling;
    for (int bounce = 0;; ++bounce) {
      const Vec3 origin = offset_ray_origin(x.position, x.geometric_normal, s.extent);
      const uint32_t record = guide.site(x, bounce);
      GuideVertex g = guide.vertex(record);
      if (guided_vertices && g.guided_probability > 0) ++*guided_vertices;
      const bool directional_texel = out.directional && bounce == 0;
      if (directional_texel) g = with_uniform_component(g, kDirectionalUniformProbability);
      ShadowRay shadow[kShadowRaysPerVertex];
      const EmitterGuidingCache::Site site =
          EmitterGuidingCache::vertex_site(emitter_guiding.cache, x.position, x.shading_normal, emitter_guiding.learning);
      const EmitterGuide& eg = site.guide;
      EmitterLearning learning;
      next_event_estimation(s, x, origin, throughput, g, eg, eye, rng, shadow[0], shadow[1], shadow[2], learning);
      bool arrived[3];
      Vec3 each[3];
      const Vec3 direct = connect(shadow, origin, rays, x, directional_texel ? out.texel_nee_sh1 : nullptr, &arrived,
                                  out.by_light ? &each : nullptr);
      if (out.by_light) {  // the area sample's emitter, the punctual light chosen, the sky
        out.add_light(learning.area_triangle != kEmitterPatchNone ? emitter_light_layer(learning.area_triangle) : kSkyLightLayer, each[0]);
        out.add_light(learning.punctual_index != kEmitterPatchNone ? punctual_light_layer(learning.punctual_index, s.punctual_light_layers)
                                                                     : kSkyLightLayer,
                      each[1]);
        out.add_light(kSkyLightLayer, each[2]);
      }
      if (site.learns)
        emitter_guiding.cache->learn_arrived(site, learning.patch_index, learning.value, arrived[0], learning.punctual_light,
                                             learning.punctual_value, arrived[1]);
      out.add(bounce, direct);
      if (directional_texel) out.texel_nee = direct;
      const DirectionSample d = sample_continuation(g, x, rng);
      if (subpaths) connect_to_pool(*pool, x, origin, throughput, g, bounce, eye, directional_texel, rng, out, rays);
      if (!(d.pdf > 0)) return;
      if (directional_texel) out.first_factor = sh1_direction_factor(x, d.direction);
      const Vec3 ray_throughput = throughput * continuation_weight(g, x, d);
      ++rays;
      const Hit hit = embree->intersect(origin, d.direction, INFINITY);
      guide.observe(record, g, d.direction, hit);
      if (!hit.found) {
        const Vec3 sky = ray_throughput * (subpaths ? escaped_radiance_with_subpaths(s, dot(x.geometric_normal, d.direction), eye, d.direction, d.pdf)
                                                    : escaped_radiance(s, d.direction, d.pdf));
        out.add(bounce, sky);
        out.add_light(kSkyLightLayer, sky);
        return;
      }
      const float emission_extra =
          subpaths ? light_subpath_emitter_hit_extra(s, dot(x.geometric_normal, d.direction), eye, eg, hit.triangle, hit.geometric_normal, hit.distance, hit.b1, hit.b2,
                                                     d.direction) : 0.0f;
      const HitResult h = shade_continuation_hit(s, hit.triangle, hit.distance, hit.b1, hit.b2, d.direction, d.pdf,
                                                 ray_throughput, bounce, limits, eg, emission_extra, rng);
      out.add(bounce, h.radiance);
      if (out.by_light && (h.radiance.x != 0 || h.radiance.y != 0 || h.radiance.z != 0))
        out.add_light(emitter_light_layer(hit.triangle), h.radiance);
      if (!h.continues) return;
      if (subpaths) eye = next_eye_subpath_vertex(eye, dot(x.geometric_normal, d.direction), h.next, hit.geometric_normal, hit.distance, d.direction, d.pdf, bounce == 0);
      throughput = h.throughput;
      x = h.next;
    }
  }

  // Incident radiance at `origin` from direction -`direction` (see ProbeEstimate). `pool`: light
  // subpaths the path from the ray's first hit connects to (that hit is its fixed x_0, as a texel is).
  Vec3 radiance_along_ray(Vec3 origin, Vec3 direction, const IntegratorSettings& settings, PathSampler& rng,
                          uint64_t& rays, bool& backface, const LightVertexPool* pool = nullptr) const {
    backface = false;
    ++rays;
    const Hit hit = embree->intersect(origin, direction, INFINITY);
    if (!hit.found) return scene_sky_radiance(scene(), direction);
    const ProbeHit h = shade_probe_hit(scene(), hit.triangle, hit.b1, hit.b2, direction);
    backface = h.back_face;
    if (!h.continues) return h.radiance;
    PathContributions contributions;
    contributions.recorded = 0;
    trace(h.next, settings, rng, contributions, rays, NoGuide{}, nullptr, {}, pool);
    return h.radiance + h.albedo * contributions.total();
  }
};

CpuReferenceIntegrator::CpuReferenceIntegrator(std::shared_ptr<const LightingScene> scene,
                                               std::shared_ptr<const EmbreeScene> embree)
    : impl_(new Impl{std::move(scene), std::move(embree)}) {}

CpuReferenceIntegrator::CpuReferenceIntegrator(const Scene& scene) : impl_(new Impl) {
  auto source = std::make_shared<const Scene>(scene);
  impl_->lighting = std::make_shared<const LightingScene>(build_lighting_scene(source, Bvh4{}));
  impl_->embree = std::make_shared<const EmbreeScene>(*source);
}

CpuReferenceIntegrator::~CpuReferenceIntegrator() { delete impl_; }

std::string CpuReferenceIntegrator::device_description() const {
  return "Embree 3 CPU reference on " + std::to_string(tbb::info::default_concurrency()) + " threads";
}

bool CpuReferenceIntegrator::auto_guiding_may_measure_light_subpaths(const IntegratorSettings& settings) const {
  return settings.guiding == GuidingMode::Auto && settings.guiding_auto_candidate != AutoGuidingCandidate::Grid;
}

LightmapEstimate CpuReferenceIntegrator::bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const {
  if (settings.integrator == IntegratorMode::Bounces) {
    if (settings.directional != DirectionalMode::Off)
      throw std::invalid_argument("CPU backend: --directional sh1 applies to path tracing, not to --integrator bounces");
    if (settings.guiding != GuidingMode::Off)
      throw std::invalid_argument("CPU backend: guiding applies to path tracing, not to --integrator bounces");
    if (settings.emitter_guiding && distributed(settings.work_share))
      throw std::invalid_argument("CPU backend: --emitter-guiding runs in one process only, not under mpirun with several ranks");
    if (settings.adaptive)
      throw std::invalid_argument("CPU backend: adaptive sampling applies to path tracing, not to --integrator bounces");
    if (settings.light_subpaths)
      throw std::invalid_argument("CPU backend: --light-paths applies to path tracing, not to --integrator bounces");
    return bake_per_bounce(*impl_->lighting, *impl_->embree, gbuffer, settings);
  }
  if (settings.light_subpaths && settings.guiding != GuidingMode::Off)
    throw std::invalid_argument("CPU backend: --light-paths does not combine with --guiding grid, svo or auto yet (use --guiding off)");
  if (settings.light_subpaths && !(settings.light_subpaths_per_sample > 0 && settings.light_subpaths_per_sample <= 64))
    throw std::invalid_argument("CPU backend: light subpaths per sample must be in (0, 64]");
  const auto start = std::chrono::steady_clock::now();
  // Split over processes (work_share.h): this rank estimates the texels [bounds[rank], bounds[rank + 1]).
  WorkShare* share = distributed(settings.work_share);
  if (share && (settings.guiding != GuidingMode::Off || settings.adaptive || settings.target_relative_error > 0))
    throw std::invalid_argument("CPU backend: guiding, adaptive sampling and --target-error (planned samples) run in "
                                "one process only, not under mpirun with several ranks");
  // Started first, so the time budget covers the allocations below too.
  PassPolicy policy;
  policy.ramp = true;  // small passes early so progress and the time budget are honoured; larger later
  // Emitter guiding folds at EmitterGuidingCache::folds_after's points: while every vertex learns,
  // passes that double to reach them (the Vulkan backend's schedule too).
  if (settings.emitter_guiding) policy.doubling_below = EmitterGuidingCache::kEveryLearningSamples;
  PassScheduler passes(settings, policy);
  const size_t texel_count = gbuffer.texels.size();
  LightmapEstimate estimate;
  estimate.recorded_bounces = std::clamp(settings.recorded_bounces, 1, kMaxRecordedBounces);
  estimate.texels.resize(texel_count);
  estimate.bounces.assign(size_t(estimate.recorded_bounces) * texel_count * 3, 0.0);
  const bool directional = settings.directional == DirectionalMode::Sh1;
  if (directional) estimate.sh1.assign(texel_count * 9, 0.0);
  // Light layers: not gathered over ranks (as on Vulkan, LightmapDriver), so one process only.
  estimate.light_layers = settings.light_layers && !share ? int(impl_->lighting->light_layer_count) : 0;
  estimate.light_sums.assign(size_t(estimate.light_layers) * texel_count * 3, 0.0);
  tbb::combinable<uint64_t> rays_per_thread([] { return uint64_t(0); });
  tbb::combinable<uint64_t> nonfinite_per_thread([] { return uint64_t(0); });
  tbb::combinable<uint64_t> guided_per_thread([] { return uint64_t(0); });
  std::vector<size_t> bounds = share ? split_by_cost(texel_count, {}, share->ranks()) : std::vector<size_t>{};
  std::vector<uint64_t> texel_rays(share ? texel_count : 0);  // this pass's, per texel: the next split's cost
  tbb::combinable<uint64_t> shared_samples_per_thread([] { return uint64_t(0); });  // this rank's (stats.rank_work)

  // Light subpaths (light_subpaths.h): with --light-paths on for every sample; with --guiding auto as
  // its candidate (AutoGuidingCandidate) where the scene has a light they start from, for the samples
  // the choice gives them.
  const bool auto_guiding = settings.guiding == GuidingMode::Auto;
  const LightSubpathSampling subpath_start =
      settings.light_subpaths || auto_guiding ? light_subpath_start(*impl_->lighting) : light_subpaths_none();
  const bool scene_starts_subpaths = light_subpaths_start_anywhere(subpath_start);
  const bool long_enough = light_subpath_pilots_fit(settings.spp);
  const bool auto_light_subpaths =
      auto_guiding_may_measure_light_subpaths(settings) &&
      (settings.guiding_auto_candidate == AutoGuidingCandidate::LightSubpaths || (scene_starts_subpaths && long_enough));
  const bool light_subpaths = scene_starts_subpaths && (settings.light_subpaths || auto_light_subpaths);

  // Built inside the timed bake: guided results are measured with the cost of their guiding data.
  std::unique_ptr<GridGuidingCache> guide;
  if (settings.guiding == GuidingMode::Grid || (auto_guiding && !auto_light_subpaths)) {
    GridGuidingConfig config;
    config.mix = settings.guiding_mix;
    config.cells_on_longest_axis = settings.guiding_grid_cells;
    guide = std::make_unique<GridGuidingCache>(*impl_->lighting, gbuffer, config);
  }
  // SVO guiding: fields rebuilt after the passes that reach 1, 2, 4, ... samples per texel (the first
  // pass unguided unless the octree already holds exitance), their rays traced by Embree.
  std::unique_ptr<SvoGuidingFields> svo_guide;
  uint32_t svo_next_rebuild = 1;
  bool svo_counting = false;  // this pass counts vertices per node: the pass that ends at a rebuild
  if (settings.guiding == GuidingMode::Svo) {
    if (!settings.guiding_octree)
      throw std::invalid_argument("CPU backend: --guiding svo needs the bake's sparse voxel octree (not --voxel-resolution none)");
    std::shared_ptr<const EmbreeScene> embree = impl_->embree;
    svo_guide = std::make_unique<SvoGuidingFields>(*impl_->lighting, *settings.guiding_octree, gbuffer,
                                                   svo_guiding_config(settings),
                                                   [embree](Vec3 origin, Vec3 direction) {
                                                     const Hit h = embree->intersect(origin, direction, INFINITY);
                                                     return GuideRayHit{h.found, h.distance, h.triangle};
                                                   });
    if (svo_guide->seeded()) svo_guide->rebuild(nullptr, 0, settings.seed);
  }
  // Emitter guiding: learned from every pass's next-event samples, folded where folds_after says.
  const std::unique_ptr<EmitterGuidingCache> emitter_guide = EmitterGuidingCache::for_bake(*impl_->lighting, gbuffer, settings);
  if (emitter_guide && share)
    throw std::invalid_argument("CPU backend: --emitter-guiding runs in one process only, not under mpirun with several ranks");
  // --guiding auto (guiding_choice.h): regions are the guide's records (grid cell x normal class of
  // the texel), the unit whose learned table decides how well its texels' first vertices are guided,
  // with at least 16 texels each, so a region's variance sums are not one texel's noise. Texels
  // without a record share one more region.
  // The light-subpath candidate has the same regions (the grid's records, no tables), a shorter
  // pilot (nothing learns) and statistics from its first sample.
  std::unique_ptr<GuidingChoice> choice;
  if (auto_guiding) {
    const GuideGridLocator locator = guide ? guide->locator()
                                           : GuideGridLocator(impl_->lighting->bounds_lo, impl_->lighting->bounds_hi, gbuffer,
                                                              settings.guiding_grid_cells, GridGuidingCache::kMinTexelsPerRecord);
    const uint32_t pilot = GuidingChoice::pilot_for(settings.spp, guide ? kGuidingLearningSamples : kLightSubpathPilotSamples);
    std::vector<uint32_t> region(texel_count);
    for (size_t i = 0; i < texel_count; ++i) {
      const uint32_t r = locator.record_of(gbuffer.texels[i].position, gbuffer.texels[i].shading_normal);
      region[i] = r == GuideGridLocator::kNoRecord ? locator.record_count() : r;
    }
    choice = std::make_unique<GuidingChoice>(std::move(region), locator.record_count() + 1, pilot, guide ? pilot / 4 : 0,
                                             settings.seed);
    if (!guide) choice->set_candidate_half_second();  // so that a short bake can abandon it unmeasured
  }

  // Adaptive sampling (adaptive_sampling_plan.h): a uniform pilot, then per-texel rates from the
  // neighbours' pilot samples. A target error always plans: a rule that stopped a texel on its own
  // running error would be biased.
  const bool adaptive = settings.adaptive || settings.target_relative_error > 0;
  std::vector<TexelSampleSums> pilot_sums(adaptive ? texel_count : 0);
  // Pilot samples per texel (a ramp boundary, so no pass crosses it). With --guiding auto measuring
  // light subpaths, the plan waits for the choice: where texels connect, its pilot is the samples
  // after the choice's (as many again), so the rates come from the strategy each texel keeps
  // (planned from the choice's pilot, mostly unconnected samples, they cost ajar_room 1.5x the
  // relMSE at 20 s: bench/results/guiding-auto-light-paths.md); where none connects, the plan is
  // made at the choice from its pilot's samples.
  const uint32_t plan_from = choice && auto_light_subpaths ? choice->pilot() : 0;
  const uint32_t usual_pilot = settings.spp != 0 && settings.spp < 64 ? 4 : 16;
  uint32_t pilot = plan_from > 0 ? 2 * plan_from : usual_pilot;
  AdaptivePlan plan;
  std::vector<uint32_t> planned;  // target-error mode: each texel's samples
  bool planning = false;          // past the pilot
  double progress_after_pilot = 0, planned_progress = 0;

  // Light subpaths: a pool per pass, or per chunk of a large pass's samples, of
  // light_subpaths_per_sample subpaths per texel sample it serves.
  const int subpath_depth = light_subpath_depth(settings);
  LightVertexPool light_pool;
  uint64_t pool_rays = 0;  // all pools': with the subpaths traced, the price of a connected sample's share
  // The share of texel samples that connect: every one with --light-paths on; with auto, in the
  // pilot's second half the measuring texels' (a quarter of them), then the texels whose regions
  // kept connections (connected_share).
  double connected_share = light_subpaths && !auto_light_subpaths ? 1.0 : 0.0;
  auto pass_connected_share = [&](uint32_t begin, uint32_t samples) -> double {
    return light_subpaths && auto_light_subpaths ? choice->candidate_share(begin, samples) : connected_share;
  };
  // Per texel, pilot samples dropped when it began to connect (their sample indices stay used).
  std::vector<uint32_t> dropped;
  auto trace_light_pool = [&](double texel_samples, uint32_t key) {
    const uint64_t paths = light_subpaths_for(texel_samples, settings.light_subpaths_per_sample);
    EmitterGuidingCache* emitter_cache = emitter_guide && emitter_guide->active() ? emitter_guide.get() : nullptr;
    light_pool = trace_light_vertex_pool(*impl_->lighting, *impl_->embree, subpath_start, paths, settings.seed, key,
                                         settings.sampler, subpath_depth, settings.russian_roulette_start, emitter_cache);
    rays_per_thread.local() += light_pool.rays;
    pool_rays += light_pool.rays;
    estimate.light_subpaths += light_pool.paths;
    estimate.light_subpath_vertices += light_pool.vertices.size();
  };

  // Auto with light subpaths: a texel whose verdict is to connect drops its pilot's samples, mostly
  // unconnected ones. Where connections pay, those carry the heavy tail that connections remove (rare
  // paths through a gap): kept, 256 of them raised ajar_room's relMSE 2x after 9 000 connected samples
  // (bench/results/guiding-auto-light-paths.md). Unbiased as the choice is: whether a texel drops is
  // its region's verdict from other texels' samples, not its own values, and its estimate is then the
  // mean of a number of later samples fixed without them.
  auto drop_pilot_of_connecting_texels = [&]() {
    dropped.assign(texel_count, 0);
    const int layers = estimate.recorded_bounces;
    for (size_t i = 0; i < texel_count; ++i) {
      if (!choice->sample_guided(i, choice->pilot())) continue;
      dropped[i] = estimate.texels[i].samples;
      estimate.pilot_samples_dropped += dropped[i];
      estimate.texels[i] = TexelAccumulator{};
      for (int k = 0; k < layers; ++k) std::fill_n(&estimate.bounces[(size_t(k) * texel_count + i) * 3], 3, 0.0);
      if (directional) std::fill_n(&estimate.sh1[i * 9], 9, 0.0);
      for (int k = 0; k < estimate.light_layers; ++k) std::fill_n(&estimate.light_sums[(size_t(k) * texel_count + i) * 3], 3, 0.0);
    }
  };
  // Whether the bake goes on long enough after the pilot for dropping it to pay: at least as many
  // samples again (--spp), or a third of the time budget spent at most.
  auto room_after_pilot = [&](const PassScheduler& p, uint32_t pilot) {
    if (settings.spp != 0) return settings.spp >= 2 * pilot;
    if (settings.time_budget_seconds > 0) return p.elapsed_seconds() < settings.time_budget_seconds / 3;
    return true;
  };

  // One sample `s` of texel `i`.
  auto take_sample = [&](size_t i, uint32_t s, bool learning, PathContributions& contributions) {
    uint64_t& rays = rays_per_thread.local();
    uint64_t& guided_vertices = guided_per_thread.local();
    // Auto: this sample's strategy (the pilot's halves on measuring texels, then the texel's
    // leave-one-out choice from its region's and the scene's evidence); unguided samples
    // trace without the guide, so regions that chose cosine pay nothing for it.
    const bool guided_sample = !choice || choice->sample_guided(i, s);
    GridGuidingCache* sample_guide = guided_sample ? guide.get() : nullptr;
    const bool connects = light_subpaths && (!auto_light_subpaths || guided_sample);
    const LiveTexel& texel = gbuffer.texels[i];
    const SurfacePoint point{texel.position, texel.geometric_normal, texel.shading_normal};
    TexelAccumulator& acc = estimate.texels[i];
    // Auto: each strategy on its own sequence, by its own count (guiding_choice.h says why).
    PathSampler rng = choice ? path_sampler(settings.seed, guided_sample ? GuidingChoice::guided_stream(i) : i,
                                            choice->strategy_sample_index(i, s, guided_sample), settings.sampler)
                             : path_sampler(settings.seed, i, s, settings.sampler);
    contributions = PathContributions{};
    contributions.recorded = estimate.recorded_bounces;
    contributions.directional = directional;
    // This thread's per-layer scratch, cleared for each sample.
    thread_local std::vector<Vec3> by_light;
    if (estimate.light_layers > 0) {
      by_light.assign(size_t(estimate.light_layers), Vec3{0, 0, 0});
      contributions.by_light = by_light.data();
    }
    const uint64_t rays_before = rays, guided_before = guided_vertices;
    EmitterGuidingCache* emitter_cache = emitter_guide && emitter_guide->active() ? emitter_guide.get() : nullptr;
    const EmitterGuiding emitter_guiding{emitter_cache, emitter_cache ? EmitterGuidingCache::learning(s)
                                                                           : EmitterGuidingCache::Learning::None};
    if (svo_guide)
      impl_->trace(point, settings, rng, contributions, rays,
                   Impl::SvoGuide{*svo_guide, svo_counting, settings.guiding_svo_texels}, &guided_vertices,
                   emitter_guiding);
    else if (sample_guide)
      impl_->trace(point, settings, rng, contributions, rays, Impl::GridGuide{*impl_, *sample_guide, learning},
                   &guided_vertices, emitter_guiding);
    else
      impl_->trace(point, settings, rng, contributions, rays, Impl::NoGuide{}, &guided_vertices, emitter_guiding,
                   connects ? &light_pool : nullptr);
    const Vec3 total = contributions.total();
    Vec3 l1[3];
    bool l1_finite = true;
    if (directional)
      for (int axis = 0; axis < 3; ++axis) l1[axis] = contributions.sh1(axis), l1_finite = l1_finite && is_finite(l1[axis]);
    if (!is_finite(total) || !l1_finite) {
      ++nonfinite_per_thread.local();
      return;  // counted and reported; an unbiased estimator never produces these
    }
    for (int c = 0; c < 3; ++c) {
      acc.total[c] += total[c];
      acc.total_squared[c] += double(total[c]) * double(total[c]);
      acc.direct[c] += contributions.by_bounce[0][c];
    }
    for (int k = 0; k < estimate.recorded_bounces; ++k)
      for (int c = 0; c < 3; ++c)
        estimate.bounces[(size_t(k) * texel_count + i) * 3 + size_t(c)] += contributions.by_bounce[k][c];
    if (directional)
      for (int axis = 0; axis < 3; ++axis)
        for (int c = 0; c < 3; ++c) estimate.sh1[(i * 3 + size_t(axis)) * 3 + size_t(c)] += l1[axis][c];
    for (int k = 0; k < estimate.light_layers; ++k)
      for (int c = 0; c < 3; ++c) estimate.light_sums[(size_t(k) * texel_count + i) * 3 + size_t(c)] += by_light[size_t(k)][c];
    ++acc.samples;
    if (choice && !choice->decided())
      choice->record(i, s, guided_sample, luminance(total), rays - rays_before, guided_vertices - guided_before);
    if (share) texel_rays[i] += rays - rays_before, ++shared_samples_per_thread.local();
    if (adaptive && !planning) {
      TexelSampleSums& p = pilot_sums[i];
      const double y = luminance(total);
      ++p.samples, p.rays += rays - rays_before, p.sum += y, p.sum_squared += y * y;
    }
  };
  // Texel `i`'s planned samples once the run has progressed `progress` samples per texel past the
  // pilot: a hashed offset in [0, 1) makes the expected count exact.
  auto planned_count = [&](size_t i, double progress) -> uint32_t {
    if (!planned.empty() && progress >= planned_progress) return planned[i];
    const double offset = double(splitmix64(settings.seed ^ (0xADA9ull << 40) ^ i) >> 11) * 0x1.0p-53;
    const double extra = std::floor(double(plan.rate[i]) * progress + offset);
    const uint32_t count = uint32_t(std::min<double>(extra + pilot, 0xFFFFFFF0u));
    return planned.empty() ? count : std::min(planned[i], count);
  };

  uint32_t first = 0, count = 0;
  double fraction = 1;
  const double loop_start = passes.elapsed_seconds();
  while (passes.next_pass(first, count, &fraction)) {
    const double connecting = pass_connected_share(first, count);
    const bool learning = guide && first < (choice ? choice->pilot() : kGuidingLearningSamples) &&
                          (!choice || !choice->decided());
    // SVO bins come from the vertices of the pass that reaches the next rebuild (the thesis's
    // previous frame): counts of earlier passes would describe older fields' paths.
    svo_counting = svo_guide && first + count >= svo_next_rebuild;
    if (planning) {
      const double progress = double(first) - progress_after_pilot + double(count) * fraction;
      if (connecting > 0) trace_light_pool(double(texel_count) * double(count) * fraction * connecting, first);
      tbb::parallel_for(tbb::blocked_range<size_t>(0, texel_count, 16), [&](const tbb::blocked_range<size_t>& range) {
        PathContributions contributions;
        for (size_t i = range.begin(); i != range.end(); ++i)
          for (uint32_t s = estimate.texels[i].samples + (dropped.empty() ? 0 : dropped[i]), target = planned_count(i, progress);
               s < target; ++s)
            take_sample(i, s, learning, contributions);
      });
    } else {
      // The last pass of a time budget may cover only part of the texels: a hashed choice spread over
      // the whole atlas (so the pass costs its fraction of a full one), different for every sample.
      const uint64_t covered_below = fraction < 1 ? uint64_t(fraction * 0x1.0p53) : UINT64_MAX;
      const uint64_t salt = splitmix64(settings.seed ^ (uint64_t(first) << 32));
      const size_t own_begin = share ? bounds[size_t(share->rank())] : 0;
      const size_t own_end = share ? bounds[size_t(share->rank()) + 1] : texel_count;
      const auto pass_start = std::chrono::steady_clock::now();
      auto take_samples = [&](uint32_t sample_begin, uint32_t sample_end) {
        tbb::parallel_for(tbb::blocked_range<size_t>(own_begin, own_end, 64), [&](const tbb::blocked_range<size_t>& range) {
          PathContributions contributions;
          for (size_t i = range.begin(); i != range.end(); ++i) {
            if (covered_below != UINT64_MAX && (splitmix64(salt + i) >> 11) >= covered_below) continue;
            for (uint32_t s = sample_begin; s < sample_end; ++s) take_sample(i, s, learning, contributions);
          }
        });
      };
      if (connecting > 0) {
        // The same pools on every rank: sized by the whole atlas's covered texels.
        const double covered = double(texel_count) * std::min(fraction, 1.0) * connecting;
        const uint32_t chunk = samples_per_pool(covered, settings.light_subpaths_per_sample);
        for (uint32_t sample_begin = first, sample_end; sample_begin < first + count; sample_begin = sample_end) {
          sample_end = sample_begin + std::min(chunk, first + count - sample_begin);
          trace_light_pool(covered * double(sample_end - sample_begin), sample_begin);
          take_samples(sample_begin, sample_end);
        }
      } else {
        take_samples(first, first + count);
      }
      if (share) {
        share->work.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - pass_start).count();
        gather_texel_sums(*share, estimate, bounds, texel_rays);
        bounds = split_by_cost(texel_count, texel_rays, share->ranks());
        std::fill(texel_rays.begin(), texel_rays.end(), 0);
      }
    }
    if (learning) guide->swap();  // this pass's learning becomes the next pass's frozen table
    if (emitter_guide && EmitterGuidingCache::folds_after(first + count)) emitter_guide->end_pass(first + count);
    if (svo_guide && svo_counting) {  // this pass reached the next rebuild and counted its vertices
      svo_guide->rebuild(&estimate, double(count) * fraction, settings.seed);
      svo_next_rebuild = 2 * (first + count);
    }
    passes.finish_pass(rays_per_thread.combine(std::plus<uint64_t>()));
    // Auto with light subpaths under a time budget: while no candidate sample has been taken (the
    // pilot's first half), a bake whose pass rate promises fewer than kLightSubpathPilots pilots
    // abandons the candidate and runs on as the unguided bake (kLightSubpathPilots says why).
    if (choice && auto_light_subpaths && !choice->decided() && settings.time_budget_seconds > 0 && fraction == 1 &&
        passes.samples_done() >= 4 && passes.samples_done() <= choice->pilot() / 2) {
      const double elapsed = passes.elapsed_seconds();
      const double per_sample = (elapsed - loop_start) / double(passes.samples_done());
      if (!light_subpath_pilots_promised(passes.samples_done(), per_sample, settings.time_budget_seconds - elapsed, choice->pilot())) {
        choice->abandon();
        estimate.guiding_auto_abandoned_at = passes.samples_done();
        if (adaptive && !planning) pilot = std::max(passes.samples_done(), usual_pilot);
      }
    }
    // Auto: the pilot is complete on every texel; each texel takes its region's cheaper strategy from
    // here. A connected sample's share of the pools: their rays per subpath x subpaths per sample.
    if (choice && !choice->decided() && passes.samples_done() >= choice->pilot() && fraction == 1) {
      if (auto_light_subpaths && estimate.light_subpaths > 0)
        choice->set_guided_sample_cost(double(pool_rays) / double(estimate.light_subpaths) * settings.light_subpaths_per_sample);
      choice->decide();
      if (auto_light_subpaths && light_subpaths) {
        connected_share = choice->guided_share();
        if (room_after_pilot(passes, choice->pilot())) drop_pilot_of_connecting_texels();
      }
      if (adaptive && !planning && plan_from > 0) {
        if (connected_share > 0)
          std::fill(pilot_sums.begin(), pilot_sums.end(), TexelSampleSums{});  // the plan's pilot: [plan_from, 2 plan_from)
        else
          pilot = passes.samples_done();  // nothing connects: plan now, from the choice's pilot
      }
    }
    if (adaptive && !planning && passes.samples_done() == pilot && fraction == 1) {
      // The pilot is complete: every texel's rate from its neighbours' pilot samples.
      plan = plan_adaptive_rates(gbuffer, pilot_sums);
      pilot_sums = {};
      planning = true;
      estimate.adaptive_pilot = pilot;
      progress_after_pilot = passes.samples_done();
      if (settings.target_relative_error > 0) {
        const uint32_t most = settings.spp ? std::max(pilot, settings.spp) : kMostSamplesForTarget;
        planned.resize(texel_count);
        double extra = 0;
        for (size_t i = 0; i < texel_count; ++i) {
          planned[i] = samples_for_target(plan.relative_deviation[i], settings.target_relative_error, pilot, most);
          // A texel that dropped its choice pilot's samples takes as many more (its indices run on).
          if (!dropped.empty()) planned[i] = uint32_t(std::min<uint64_t>(uint64_t(planned[i]) + dropped[i], 0xFFFFFFF0u));
          extra += planned[i] - pilot;
        }
        // Every texel reaches its count when the progress reaches the mean extra samples per texel.
        planned_progress = extra / double(std::max<size_t>(texel_count, 1));
        for (size_t i = 0; i < texel_count; ++i)
          plan.rate[i] = planned_progress > 0 ? float((planned[i] - pilot) / planned_progress) : 0.0f;
        passes.set_sample_limit(uint32_t(std::min<double>(0xFFFFFFFEu, progress_after_pilot + std::ceil(planned_progress))));
      }
    }
  }
  estimate.adaptive = adaptive;
  estimate.rays = rays_per_thread.combine(std::plus<uint64_t>());
  estimate.nonfinite_samples = nonfinite_per_thread.combine(std::plus<uint64_t>());
  if (settings.work_share) {
    settings.work_share->work.rays += estimate.rays;
    uint64_t samples = 0;
    for (const TexelAccumulator& t : estimate.texels) samples += t.samples;
    settings.work_share->work.texel_samples += share ? shared_samples_per_thread.combine(std::plus<uint64_t>()) : samples;
  }
  if (share) {
    estimate.rays = share->sum(estimate.rays);
    estimate.nonfinite_samples = share->sum(estimate.nonfinite_samples);
  }
  estimate.guided_vertices = guided_per_thread.combine(std::plus<uint64_t>());
  if (choice) {
    estimate.guiding_auto = true;
    estimate.guiding_auto_light_subpaths = auto_light_subpaths;
    estimate.guiding_auto_pilot = choice->pilot();
    if (choice->decided() && !choice->abandoned()) estimate.guiding_regions = choice->regions(), estimate.guiding_scene = choice->scene();
  }
  if (guide && settings.inspect_guiding) settings.inspect_guiding(*guide);
  if (svo_guide && settings.inspect_svo_guiding) settings.inspect_svo_guiding(*svo_guide);
  if (emitter_guide) {
    emitter_guide->report(estimate.emitter_guiding);
    if (settings.inspect_emitter_guiding) settings.inspect_emitter_guiding(*emitter_guide);
  }
  estimate.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (settings.work_share && !share) settings.work_share->work.seconds += estimate.seconds;
  return estimate;
}

ProbeEstimate CpuReferenceIntegrator::bake_probes(const std::vector<Vec3>& positions,
                                                  const IntegratorSettings& settings) const {
  const auto start = std::chrono::steady_clock::now();
  const size_t probe_count = positions.size();
  ProbeEstimate estimate;
  estimate.sh_sum.assign(probe_count, std::array<double, 27>{});
  estimate.axis_irradiance_sum.assign(probe_count, std::array<double, 18>{});
  estimate.samples.assign(probe_count, 0);
  estimate.backface_hits.assign(probe_count, 0);
  tbb::combinable<uint64_t> rays_per_thread([] { return uint64_t(0); });
  tbb::combinable<uint64_t> nonfinite_per_thread([] { return uint64_t(0); });
  const uint32_t spp = settings.spp == 0 ? 0xFFFFFFFFu : settings.spp;
  PassPolicy policy;
  // One complete stratified set per pass, so stopping on the time budget never leaves strata out.
  policy.largest_pass = kProbeStratifiedSetSize;
  policy.stratified_set = kProbeStratifiedSetSize;
  PassScheduler passes(settings, policy);
  // Split over processes (work_share.h) as the texels are: global probe indices, gathered after every pass.
  WorkShare* share = distributed(settings.work_share);
  std::vector<size_t> bounds = share ? split_by_cost(probe_count, {}, share->ranks()) : std::vector<size_t>{};
  std::vector<uint64_t> probe_rays(share ? probe_count : 0);  // this pass's: the next split's cost
  uint64_t own_samples = 0;
  // Light subpaths (--light-paths on): every probe sample's path connects to a pool traced for its
  // chunk of samples, as texels' do (light_subpaths_per_sample subpaths per probe sample; the keys'
  // top bit keeps the probes' pools apart from the texels'). Without emitter guiding, as probes' NEE.
  const LightSubpathSampling subpath_start = settings.light_subpaths ? light_subpath_start(*impl_->lighting) : light_subpaths_none();
  const bool light_subpaths = light_subpaths_start_anywhere(subpath_start);
  const int subpath_depth = light_subpath_depth(settings);
  LightVertexPool light_pool;
  uint32_t first = 0, count = 0;
  while (passes.next_pass(first, count)) {
    const size_t own_begin = share ? bounds[size_t(share->rank())] : 0;
    const size_t own_end = share ? bounds[size_t(share->rank()) + 1] : probe_count;
    const auto pass_start = std::chrono::steady_clock::now();
    // The same pools on every rank: sized by all probes.
    const uint32_t chunk = light_subpaths ? samples_per_pool(double(probe_count), settings.light_subpaths_per_sample) : count;
    for (uint32_t sample_begin = first, sample_end; sample_begin < first + count; sample_begin = sample_end) {
      sample_end = sample_begin + std::min(chunk, first + count - sample_begin);
      if (light_subpaths) {
        const uint64_t paths =
            light_subpaths_for(double(probe_count) * double(sample_end - sample_begin), settings.light_subpaths_per_sample);
        light_pool = trace_light_vertex_pool(*impl_->lighting, *impl_->embree, subpath_start, paths, settings.seed,
                                             sample_begin | 0x80000000u, settings.sampler, subpath_depth,
                                             settings.russian_roulette_start, nullptr);
        rays_per_thread.local() += light_pool.rays;
        estimate.light_subpaths += light_pool.paths;
      }
      tbb::parallel_for(tbb::blocked_range<size_t>(own_begin, own_end, 1), [&](const tbb::blocked_range<size_t>& range) {
        uint64_t& rays = rays_per_thread.local();
        uint64_t& nonfinite = nonfinite_per_thread.local();
        for (size_t i = range.begin(); i != range.end(); ++i) {
          const uint64_t rays_before = rays;
          for (uint32_t s = sample_begin; s < sample_end; ++s) {
            PathSampler rng = path_sampler(settings.seed, kProbeRngStreamBase + i, s, settings.sampler);
            const Vec3 direction = probe_ray_direction(s, spp, rng);
            bool backface = false;
            const Vec3 radiance = impl_->radiance_along_ray(positions[i], direction, settings, rng, rays, backface,
                                                            light_subpaths ? &light_pool : nullptr);
            if (backface) ++estimate.backface_hits[i];
            if (!is_finite(radiance)) {
              ++nonfinite;
              continue;
            }
            const ShBasis y = sh_basis(direction);
            for (int k = 0; k < kShCoefficients; ++k)
              for (int c = 0; c < 3; ++c)
                estimate.sh_sum[i][size_t(k) * 3 + size_t(c)] += double(radiance[c]) * double(y[k]) * double(kShSphereMeasure);
            for (int axis = 0; axis < 6; ++axis) {
              const float cosine = (axis % 2 ? -1.0f : 1.0f) * direction[axis / 2];
              if (cosine <= 0) continue;
              for (int c = 0; c < 3; ++c)
                estimate.axis_irradiance_sum[i][size_t(axis) * 3 + size_t(c)] += double(radiance[c]) * cosine * 4.0;
            }
            ++estimate.samples[i];
          }
          if (share) probe_rays[i] += rays - rays_before;
        }
      });
    }
    if (share) {
      share->work.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - pass_start).count();
      own_samples += uint64_t(own_end - own_begin) * count;
      allgather_items(*share, estimate.sh_sum.data(), 1, bounds);
      allgather_items(*share, estimate.axis_irradiance_sum.data(), 1, bounds);
      allgather_items(*share, estimate.samples.data(), 1, bounds);
      allgather_items(*share, estimate.backface_hits.data(), 1, bounds);
      allgather_items(*share, probe_rays.data(), 1, bounds);
      bounds = split_by_cost(probe_count, probe_rays, share->ranks());
      std::fill(probe_rays.begin(), probe_rays.end(), 0);
    }
    passes.finish_pass(rays_per_thread.combine(std::plus<uint64_t>()));
  }
  estimate.rays = rays_per_thread.combine(std::plus<uint64_t>());
  estimate.nonfinite_samples = nonfinite_per_thread.combine(std::plus<uint64_t>());
  estimate.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (settings.work_share) {
    RankWork& work = settings.work_share->work;
    work.rays += estimate.rays;
    if (share) {
      work.probe_samples += own_samples;
    } else {
      for (uint32_t n : estimate.samples) work.probe_samples += n;
      work.seconds += estimate.seconds;
    }
  }
  if (share) {
    estimate.rays = share->sum(estimate.rays);
    estimate.nonfinite_samples = share->sum(estimate.nonfinite_samples);
  }
  return estimate;
}

}  // namespace exitance
