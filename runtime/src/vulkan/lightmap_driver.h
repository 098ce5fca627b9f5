// Integrator::bake on the wavefront: the live texels are the work items; the PassScheduler's passes
// of samples are cut into batches of at most work_items_per_batch (texel, sample) items; with a
// target error, converged texels leave the work list between passes.
//
// The same steps, kept on the device between calls, are the runtime's progressive accumulation:
// start() uploads the texels and clears their sums, add_samples() adds samples to every texel,
// read() downloads the sums. bake() and the probe driver reuse the buffers, so bake() ends a
// progressive accumulation, and start points a probe bake overwrote are uploaded again.
#pragma once
#include <memory>
#include <optional>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "device_lightmaps.h"
#include "guide_fold_kernel.h"
#include "light_subpath_pools.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

// What grid guiding reads of the scene (GridGuidingCache's bounds and radiance scale); the
// integrator keeps it current through scene edits.
struct GuidingScene {
  Vec3 bounds_lo{0, 0, 0}, bounds_hi{0, 0, 0};
  float reference_radiance = 1;
  // SVO guiding's fields trace their capture rays here (core BVH) and read emission and sky: the
  // scene the integrator was created on.
  std::shared_ptr<const LightingScene> lighting;
};

class LightmapDriver {
 public:
  explicit LightmapDriver(WavefrontBatchRunner& runner) : runner_(runner) {}
  void set_guiding_scene(const GuidingScene& scene) { guiding_scene_ = scene; }
  const GuidingScene& guiding_scene() const { return guiding_scene_; }
  LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings);
  // --guiding auto: whether its candidate in this bake is light subpaths (a light starts them and
  // the bake fits their pilots, or they are named). Where it is not and grid guiding is not named,
  // bake() measures nothing (lightmap_driver.cpp says why).
  bool auto_measures_light_subpaths(const IntegratorSettings& settings) const;

  // `changed_light_pairs` > 0: the accumulation estimates the change of direct light from that many
  // edited punctual lights (GpuParams::changed_light_pairs; their records set on the scene first).
  // `texels_as_before`: the G-buffer's texels are those of the running accumulation (an edit that
  // moved none): their start points are not derived and uploaded again, only the sums cleared.
  // `accumulation_cleared`: the sums were cleared since the last pass (LightmapPublisher::publish
  // with clear_accumulation): not cleared again unless their buffers had to grow.
  // `changed_light_layers`: the light layer of each changed light (light layers on).
  void start(const TexelGBuffer& gbuffer, const IntegratorSettings& settings, uint32_t changed_light_pairs = 0,
             bool texels_as_before = false, bool accumulation_cleared = false, const std::vector<uint32_t>& changed_light_layers = {});
  // The scene's lights changed under a running accumulation (an edit that only scaled them): the
  // parameters the kernels take from the scene (the constant sky, counts) read again, and the light
  // subpaths' start (its probabilities follow the lights' power) made for the edited scene.
  void scene_changed();
  // The running accumulation's light subpaths as `settings` asks from its next pass on
  // (VulkanIntegrator::set_progressive_light_subpaths); nothing before a start.
  void set_light_subpaths(const IntegratorSettings& settings);
  // `samples` more per texel (sample indices continue where the last call ended); returns the rays traced.
  uint64_t add_samples(uint32_t samples);
  // The start points of `texels` taken from `gbuffer` again (an edit moved them), on the host and,
  // where the texel buffers are the accumulation's, on the device. Nothing before a start.
  void update_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& texels);
  // Samples [first_sample, first_sample + samples) of the listed texels only (indices into the
  // G-buffer, each at most once); the caller keeps each texel's count. Returns the rays traced.
  uint64_t add_samples_to(const std::vector<uint32_t>& texels, uint32_t first_sample, uint32_t samples);
  LightmapEstimate read();
  // The sums of a device estimate (device_lightmaps.h), read back, with the progressive
  // accumulation's rays, seconds and counters.
  LightmapEstimate read(const DeviceLightmap& lightmap);
  // The accumulation's texels, recorded layers and L1 sums; throws std::logic_error before a start.
  struct Shape {
    size_t texels = 0;
    int layers = 1;
    bool directional = false;
    int light_layers = 0;
  };
  Shape shape() const;
  bool started() const { return progressive_.has_value(); }
  // Another bake takes the texel buffers (the per-bounce mode): the progressive accumulation ends.
  void end_progressive() { progressive_.reset(); }
  uint32_t samples_done() const { return progressive_ ? progressive_->next_sample : 0; }

 private:
  // What one accumulation keeps between its passes.
  struct Accumulation {
    std::vector<GpuSurfacePoint> start_points;  // start()'s, to upload again after a probe bake took the buffer
    std::vector<uint32_t> work_list;
    size_t texel_count = 0;
    int recorded = 1;
    int light_layers = 0;  // IntegratorSettings::light_layers: the scene's light layers, else 0
    size_t result_bytes = 0;
    bool directional = false;  // DirectionalMode::Sh1: L1 results and sums too
    size_t max_work = 0;
    GpuParams params{};
    BatchTotals totals;
    // Light subpaths (IntegratorSettings::light_subpaths): each batch traces its own pool (null: none).
    std::shared_ptr<LightSubpathPools> light_pools;
    IntegratorSettings light_pool_settings;  // what made them: a progressive accumulation's pools are made again after a scene change
    uint32_t next_sample = 0;
    double seconds = 0;
  };

  using Runs = std::vector<std::pair<size_t, size_t>>;
  // `reuse`: an accumulation over the same texels whose start points and work list `a` takes.
  void prepare(const TexelGBuffer& gbuffer, const IntegratorSettings& settings, Accumulation& a, const Runs* bake_runs = nullptr,
               Accumulation* reuse = nullptr, bool accumulation_cleared = false);
  void upload_items(const Accumulation& a);
  // `a`'s batches trace light subpaths (settings.light_subpaths) from the integrator's current scene.
  void make_light_pools(Accumulation& a, const IntegratorSettings& settings);
  // `a`'s pools gone, its batches back to the path tracer's shadow slots (no connection slot).
  void drop_light_pools(Accumulation& a);
  void run_pass(Accumulation& a, uint32_t first, uint32_t pass);
  // What a read-back fills, made ahead of time (bake(): on a thread while the passes run): the
  // estimate's per-texel arrays for `host_texels`, zero (their memory touched), and a pinned
  // staging buffer for the largest array of `read_texels` texels (allocating it is part of a
  // read-back's cost).
  struct ReadBackSpace {
    LightmapEstimate estimate;
    Buffer staging;
  };
  static LightmapEstimate sized_estimate(size_t texels, int recorded, bool directional, int light_layers = 0);
  ReadBackSpace read_back_space(size_t host_texels, size_t read_texels, int recorded, bool directional, int light_layers = 0);
  // The sums read back into `space` (sized here when it does not fit); `only`: just these runs
  // [first, end) of texels (a rank's own), in place among all texels (the others' left zero) or,
  // `packed`, run after run in arrays of the runs' texels alone; null: every texel.
  // `from`: another estimate's buffers shaped as `a` (default: the accumulation's).
  LightmapEstimate download(const Accumulation& a, const Runs* only = nullptr, ReadBackSpace space = {}, bool packed = false,
                            const TexelAccumulators* from = nullptr);
  // The texels of `work_list` whose relative standard error is still above the target.
  std::vector<uint32_t> unconverged(const std::vector<uint32_t>& work_list, size_t texel_count, double target);

  WavefrontBatchRunner& runner_;
  GuidingScene guiding_scene_;
  std::optional<Accumulation> progressive_;
  std::unique_ptr<GuideFoldKernel> guide_fold_;    // made by the first grid-guided bake
  std::unique_ptr<GuideFoldKernel> emitter_fold_;  // made by the first emitter-guided bake
};

}  // namespace exitance::vulkan
