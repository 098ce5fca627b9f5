// What a bake asks of an integrator, whatever the backend.
#pragma once
#include <cstdint>
#include <functional>

namespace exitance {
namespace formats {
struct SparseVoxelOctree;
}

class EmitterGuidingCache;
class GridGuidingCache;
class SvoGuidingFields;
class WorkShare;

// How texels are lit (bake --integrator). Path: the unbiased path tracer of path.h, one path per
// sample. Bounces: per-bounce passes (seed 003, issue 10): B_0 = direct light; pass k+1 gathers, at
// the hits of cosine rays from every texel, the stored outgoing radiance albedo * B_k of the hit's
// lightmap texels (bilinear) - a cache lookup with a resolution bias, measured in
// bench/results/per-bounce.md. See docs/lighting-core.md, "Per-bounce mode".
enum class IntegratorMode { Path, Bounces };

// Path guiding of the continuation directions (bake --guiding, issue 11). Grid: the regular-grid
// SARSA cache of seed 002 (core/grid_guiding_cache.h), one-sample MIS with cosine sampling. Svo:
// fields built from exitance in the bake's octree (seed 000, core/svo_guiding_fields.h; needs
// guiding_octree). Auto: the integrator measures, during a pilot, the variance per counted cost of
// guided (the `guiding_auto_candidate` kind) and unguided samples per region and keeps guiding where
// it pays (core/guiding_choice.h); both backends (bake runs it on Vulkan only when --guiding auto is given).
enum class GuidingMode { Off, Grid, Svo, Auto };

// What GuidingMode::Auto measures against unguided samples (issue 35, item 4). Scene: light subpaths
// where any light starts them (emissive triangles, punctual lights, the sky) and the bake is long
// enough for their pilot (spp of kLightSubpathPilots pilots, or a time budget whose pass rate
// promises them; bench/results/guiding-auto-light-paths.md), grid guiding otherwise. Grid: grid
// guiding always. LightSubpaths: light subpaths always (a scene with no light they start from
// measures grid guiding on the Vulkan backend and nothing on the CPU's). Both backends.
enum class AutoGuidingCandidate { Scene, Grid, LightSubpaths };

// Directional lightmaps (bake --directional, issue 14). Sh1: per texel also the world-space L1 SH
// coefficients of cosine-convolved irradiance in units of E/pi (LightmapEstimate::sh1,
// docs/bundle.md "Directional layers"); the texel's first continuation then samples a defensive
// mixture with the uniform hemisphere (path.h). Path mode only; both backends (not the Vulkan
// progressive refresh).
enum class DirectionalMode { Off, Sh1 };

struct IntegratorSettings {
  IntegratorMode integrator = IntegratorMode::Path;
  // spp, time_budget_seconds and target_relative_error mean the same in both modes. Bounces: spp is
  // the samples per texel of every bounce pass (B_0: direct-light samples; k >= 1: gather rays);
  // max_bounces = N forces the passes B_0..B_N, -1 = until the extrapolated tail is below the noise;
  // every pass is recorded (recorded_bounces is ignored); the roulette settings do not apply.
  uint32_t spp = 128;              // samples per texel; 0 = until the time budget ends
  double time_budget_seconds = 0;  // 0 = no budget
  double target_relative_error = 0;  // plan each texel's samples to reach this relative standard error; 0 = off
  // Adaptive sampling (core/adaptive_sampling_plan.h): after a pilot, texels get samples in proportion
  // to their estimated relative deviation; spp is then the mean samples per texel. CPU backend, path
  // mode; the others refuse it. Off: every texel gets the same samples.
  bool adaptive = false;
  // Bounces mode: B_1 gathers B_0 at its hits by tracing one direct-light sample there (true) rather
  // than reading the B_0 lightmap (false). Direct light carries the sharp shadows a texel-resolution
  // cache blurs; traced, the lookup's resolution bias only enters from B_2 on, through the smoother B_1.
  bool trace_first_bounce = true;
  // Bounces mode on the Vulkan backend: build the layer caches on the host and upload them (the path
  // before the device built them; the same pages bit for bit), for the equivalence test and benches.
  bool bounce_caches_on_host = false;
  // Grid and emitter guiding on the Vulkan backend: fold the learned sums on the host between
  // learning passes (read back, GridGuidingCache::swap or EmitterGuidingCache::end_pass, upload: the
  // path before fold_guide.comp and fold_emitter_guide.comp), for the equivalence tests and benches.
  bool guide_fold_on_host = false;
  int max_bounces = -1;            // diffuse bounces after the first hit; -1 = until Russian roulette
  uint64_t seed = 0;
  int recorded_bounces = 4;        // layers bounce0 (= direct) .. bounce<K-1> kept separately
  // Vulkan path mode: also keep E/pi per light layer (exitance/common/light_layers.h; the runtime's
  // refresh scales a layer when only its light's emission changed). 24 bytes per layer and texel.
  bool light_layers = false;
  int russian_roulette_start = 3;  // first bounce at which roulette may end a path
  int safety_bounce_cap = 4096;    // never reached by paths of albedo < 0.998 in practice; documented
  uint32_t sampling_strategy = 0;  // continuation directions: kStrategyCosine (path.h)
  uint32_t sampler = 0;            // random numbers: kSamplerSobol (0) or kSamplerIndependent (path_sampler.h)
  GuidingMode guiding = GuidingMode::Off;  // Path mode only; backends refuse modes they lack
  DirectionalMode directional = DirectionalMode::Off;  // Path mode only
  AutoGuidingCandidate guiding_auto_candidate = AutoGuidingCandidate::Scene;  // what Auto measures against unguided
  float guiding_mix = 0.5f;         // probability of the guided component at a guided vertex (0..1)
  int guiding_grid_cells = 16;      // grid cells along the scene's longest axis (cubic cells)
  // GuidingMode::Svo: the bake's octree (its structure; exitance it holds seeds the guide), and
  // PARTITION-S's c_ray (vertices per sample per texel that make a node a bin).
  const formats::SparseVoxelOctree* guiding_octree = nullptr;
  double guiding_svo_c_ray = 512;
  uint32_t guiding_svo_rays_per_bin = 1;  // rays per hemisphere bin of an SVO field (k x k stratified)
  bool guiding_svo_emitted = true;        // SVO fields include emitted radiance (false: reflected only)
  // Whether texels' own vertices (bounce 0) sample the SVO mixture; false: cosine there, so the
  // first continuation keeps its stratified Sobol pair (bench/results/guiding-svo.md).
  bool guiding_svo_texels = true;
  // Emitter guiding (bake --emitter-guiding, core/emitter_guiding_cache.h): next-event estimation
  // samples emitter patches from a distribution learned per grid record, as one component of a
  // one-sample mixture with the default (probability emitter_guiding_mix); Path mode, CPU backend.
  bool emitter_guiding = false;
  float emitter_guiding_mix = 0.5f;
  uint32_t emitter_guiding_patches = 512;  // about this many emitter patches (guided_emitters.h)
  // Light subpaths (bake --light-paths, common/light_subpaths.h, issue 35): each sample pass also
  // traces light_subpaths_per_sample subpaths per texel sample from the emitters and point and spot
  // lights into a shared pool, and every eye vertex connects to one pool vertex, all strategies
  // combined by the power heuristic. Path mode, CPU backend; not with path guiding (emitter
  // guiding combines). 1/16 subpath per sample: bench/results/light-subpaths.md.
  bool light_subpaths = false;
  double light_subpaths_per_sample = 0.0625;
  std::function<void(double fraction_done, uint64_t rays)> progress;  // called between passes
  // The seconds the time budget has run (PassScheduler::elapsed_seconds); null: since the
  // integrator's scheduler started. bake starts it with the lighting stage, so the stage's setup
  // counts against the budget; tests drive a virtual clock (cuts that do not depend on the machine).
  std::function<double()> budget_clock;
  // Called once at the end of a guided bake with its cache (plots of the learned fields, tests).
  std::function<void(const GridGuidingCache&)> inspect_guiding;
  std::function<void(const SvoGuidingFields&)> inspect_svo_guiding;  // the same for GuidingMode::Svo
  std::function<void(const EmitterGuidingCache&)> inspect_emitter_guiding;  // the same for emitter_guiding
  // Bounces mode on the Vulkan backend: each layer cache's page words (kBounceCacheTexelWords per page
  // texel, all pages) as the layer passes read them, after every build (tests: device against host).
  std::function<void(size_t layer, const std::vector<float>& words)> inspect_bounce_cache;
  // This process's share of a bake split over processes (core/work_share.h; bake under mpirun); null:
  // the whole bake. Backends without it refuse more than one rank before lighting (bake does).
  WorkShare* work_share = nullptr;
};

}  // namespace exitance
