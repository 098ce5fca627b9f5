#include "lightmap_driver.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <stdexcept>

#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/grid_guiding_cache.h"
#include "exitance/runtime/core/guiding_choice.h"
#include "exitance/runtime/core/light_subpath_start.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/core/pass_scheduler.h"
#include "exitance/runtime/core/work_share.h"
#include "exitance/runtime/core/svo_guiding_fields.h"
#include "emitter_guide_buffer.h"
#include "guide_buffer.h"
#include "svo_guide_buffer.h"

namespace exitance::vulkan {
namespace {

constexpr int kMaxRecordedBounces = int(kMaxRecordedLayers);
using Clock = std::chrono::steady_clock;

// --guiding auto: every texel's strategy word (common/guiding_auto_strategy.h) from the choice.
std::vector<uint32_t> strategy_words(const GuidingChoice& choice, size_t texel_count) {
  std::vector<uint32_t> words(texel_count);
  for_each_chunk(texel_count, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) words[i] = choice.strategy_word(i);
  });
  return words;
}

// The device's pilot sums (GuideBuffer::download_auto_sums) into the choice, as record() would add them.
void import_strategy_sums(const std::vector<double>& sums, GuidingChoice& choice) {
  const size_t texel_count = sums.size() / (2 * kAutoSumDoubles);
  for (size_t i = 0; i < texel_count; ++i)
    for (int k = 0; k < 2; ++k) {
      const double* d = &sums[(i * 2 + size_t(k)) * kAutoSumDoubles];
      if (d[0] == 0) continue;
      StrategySums s;
      s.samples = uint32_t(d[0]);
      s.sum = d[1];
      s.sum_squared = d[2];
      s.sum_cubed = d[3];
      s.sum_fourth = d[4];
      s.rays = uint64_t(d[5]);
      s.guided_vertices = uint64_t(d[6]);
      choice.add_sums(i, k == 1, s);
    }
}

}  // namespace

// Buffers sized and bound, texels uploaded, sums cleared: an accumulation at sample 0. start()'s
// (`bake_runs` null): every texel, its start point kept on the host too (uploaded again after a
// probe bake took the buffer). bake()'s: the texels of `bake_runs` (a rank's own under a split),
// their start points written straight into the staging memory, and on the work list.
void LightmapDriver::prepare(const TexelGBuffer& gbuffer, const IntegratorSettings& settings, Accumulation& a,
                             const Runs* bake_runs, Accumulation* reuse, bool accumulation_cleared) {
  a.texel_count = gbuffer.texels.size();
  a.recorded = std::clamp(settings.recorded_bounces, 1, kMaxRecordedBounces);
  if (a.texel_count >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many texels");
  // Per work item, result slots 0..K of RGB floats; enough items per batch to keep every path slot
  // busy between drains, within the largest storage buffer.
  a.directional = settings.directional == DirectionalMode::Sh1;
  a.result_bytes = size_t(a.recorded + 1) * 12 + (a.directional ? 36 : 0);  // + 9 floats of L1 (sh1_result_index)
  if (settings.guiding == GuidingMode::Auto) a.result_bytes += kAutoCostWords * 4;  // bindings.glsl auto_cost_index
  // Light layers: L rgb floats per work item after the rest (bindings.glsl add_light_result).
  // (A rank's share of a split bake keeps none: the runtime's edits scale them, in one process.)
  a.light_layers = settings.light_layers && !distributed(settings.work_share) ? int(runner_.scene().light_layer_count()) : 0;
  const size_t words_before_light_layers = a.result_bytes / 4;
  a.result_bytes += size_t(a.light_layers) * 12;
  a.max_work = runner_.work_items_per_batch(a.result_bytes);
  a.work_list.clear();
  if (reuse) {
    a.start_points = std::move(reuse->start_points);
    a.work_list = std::move(reuse->work_list);  // on the device as the last pass left it
  } else if (bake_runs) {
    for (const auto& [first, end] : *bake_runs)
      for (size_t i = first; i < end; ++i) a.work_list.push_back(uint32_t(i));
  } else {
    a.start_points.resize(a.texel_count);
    for (size_t i = 0; i < a.texel_count; ++i) a.start_points[i] = texel_start_point(gbuffer.texels[i]);
    a.work_list.resize(a.texel_count);
    for (size_t i = 0; i < a.texel_count; ++i) a.work_list[i] = uint32_t(i);
  }
  a.params = runner_.bake_params(settings, uint32_t(a.recorded), uint32_t(a.texel_count));
  a.params.directional = a.directional ? 1u : 0u;
  a.params.light_layers = uint32_t(a.light_layers);
  a.params.punctual_layers = runner_.scene().punctual_light_layers();
  a.params.light_result_words = uint32_t(words_before_light_layers);
  if (a.texel_count == 0) return;

  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  buffers.items.reserve(context, a.texel_count);
  const VkBuffer sums_before[3] = {buffers.texels.sums.handle(), buffers.texels.bounce_sums.handle(), buffers.texels.samples.handle()};
  buffers.texels.reserve(context, a.texel_count, a.recorded + a.light_layers, a.directional);
  // Buffers that grew hold nothing yet: cleared whatever the caller cleared before.
  const bool grew = sums_before[0] != buffers.texels.sums.handle() || sums_before[1] != buffers.texels.bounce_sums.handle() ||
                    sums_before[2] != buffers.texels.samples.handle();
  buffers.results.reserve(context, a.max_work * a.result_bytes);
  runner_.bind_buffers();
  if (bake_runs) {
    constexpr size_t kPoint = sizeof(GpuSurfacePoint);
    std::vector<ByteRange> ranges;
    for (const auto& [first, end] : *bake_runs) ranges.push_back({first * kPoint, (end - first) * kPoint});
    context.write_ranges(buffers.items.start_points, ranges, [&](char* staging) {
      for (const auto& [first, end] : *bake_runs)
        for (size_t i = first; i < end; ++i, staging += kPoint) {
          const GpuSurfacePoint p = texel_start_point(gbuffer.texels[i]);
          std::memcpy(staging, &p, kPoint);
        }
    });
    if (!a.work_list.empty()) context.upload(buffers.items.batch_items, a.work_list.data(), a.work_list.size() * 4);
    buffers.items.owner = WorkItems::Owner::None;  // not start()'s texels: a later start() uploads its own
  } else if (!reuse || buffers.items.owner != WorkItems::Owner::Texels) {
    upload_items(a);
  }
  if (accumulation_cleared && !grew) return;
  VkCommandBuffer cmd = context.begin();
  buffers.texels.clear(cmd);
  context.submit_and_wait(cmd);
}

void LightmapDriver::make_light_pools(Accumulation& a, const IntegratorSettings& settings) {
  if (!guiding_scene_.lighting) throw std::logic_error("Vulkan backend: light subpaths without the integrator's scene");
  a.light_pools = std::make_shared<LightSubpathPools>(runner_, *guiding_scene_.lighting, settings, a.max_work, a.params);
  a.light_pool_settings = settings;
}

void LightmapDriver::upload_items(const Accumulation& a) {
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  context.upload(buffers.items.start_points, a.start_points.data(), a.start_points.size() * sizeof(GpuSurfacePoint));
  context.upload(buffers.items.batch_items, a.work_list.data(), a.work_list.size() * 4);
  buffers.items.owner = WorkItems::Owner::Texels;
}

// Samples [first, first + pass) of every texel on the work list, in batches of at most max_work items.
void LightmapDriver::run_pass(Accumulation& a, uint32_t first, uint32_t pass) {
  const uint32_t chunk = uint32_t(std::min(a.work_list.size(), a.max_work));
  for (size_t offset = 0; offset < a.work_list.size(); offset += chunk) {
    const uint32_t n = uint32_t(std::min<size_t>(chunk, a.work_list.size() - offset));
    if (a.light_pools) a.light_pools->before_batch(a.params, double(n) * pass);
    runner_.run(a.params, {uint32_t(offset), n, first, pass}, a.result_bytes, kTexelBatch, a.totals);
    if (a.light_pools) a.light_pools->after_batch(a.totals, a.params);
  }
}

LightmapEstimate LightmapDriver::sized_estimate(size_t texels, int recorded, bool directional, int light_layers) {
  LightmapEstimate estimate;
  estimate.recorded_bounces = recorded;
  // Hundreds of MB at millions of texels, first touched in huge pages where the kernel allows.
  formats::resize_in_huge_pages(estimate.texels, texels);
  formats::resize_in_huge_pages(estimate.bounces, size_t(recorded) * texels * 3);
  estimate.light_layers = light_layers;
  formats::resize_in_huge_pages(estimate.light_sums, size_t(light_layers) * texels * 3);
  if (directional) formats::resize_in_huge_pages(estimate.sh1, texels * 9);
  return estimate;
}

LightmapDriver::ReadBackSpace LightmapDriver::read_back_space(size_t host_texels, size_t read_texels, int recorded,
                                                              bool directional, int light_layers) {
  ReadBackSpace space;
  space.estimate = sized_estimate(host_texels, recorded, directional, light_layers);
  const size_t largest = read_texels * std::max<size_t>({size_t(recorded) * 24, size_t(light_layers) * 24, 48, directional ? 72u : 0u});
  if (largest > 0) space.staging = runner_.context().create_buffer(largest, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  return space;
}

LightmapEstimate LightmapDriver::download(const Accumulation& a, const Runs* only, ReadBackSpace space, bool packed,
                                          const TexelAccumulators* from) {
  const size_t texel_count = a.texel_count;
  const Runs all{{0, texel_count}};
  const Runs& runs = only ? *only : all;
  // Where each run's first texel goes on the host: its own index, or after the runs before it.
  std::vector<size_t> to(runs.size());
  size_t host_texels = texel_count;
  if (packed) {
    host_texels = 0;
    for (size_t k = 0; k < runs.size(); ++k) to[k] = host_texels, host_texels += runs[k].second - runs[k].first;
  } else {
    for (size_t k = 0; k < runs.size(); ++k) to[k] = runs[k].first;
  }
  LightmapEstimate estimate = space.estimate.texels.size() == host_texels && !space.estimate.texels.empty()
                                  ? std::move(space.estimate)
                                  : sized_estimate(host_texels, a.recorded, a.directional, a.light_layers);
  const Buffer* staging = space.staging.handle() ? &space.staging : nullptr;
  Buffer shared_staging;
  if (texel_count > 0) {
    Context& context = runner_.context();
    // Without a caller's staging, one buffer for every read below: each host-visible allocation of
    // tens of MB (a million texels' sums) costs its own pinning and first touch.
    size_t read_texels = 0;
    for (const auto& [first, end] : runs) read_texels += end - first;
    const size_t largest =
        read_texels * std::max<size_t>({size_t(a.recorded) * 24, size_t(a.light_layers) * 24, 48, a.directional ? 72u : 0u});
    if (!staging && largest > Context::kReusedStagingLimit) {
      shared_staging = context.create_buffer(largest, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
      staging = &shared_staging;
    }
    const TexelAccumulators& sums = from ? *from : runner_.buffers().texels;
    // The runs' bytes of a per-texel array of `texel_bytes` per texel starting at byte `base`.
    auto ranges = [&runs](size_t texel_bytes, size_t base) {
      std::vector<ByteRange> r;
      for (const auto& [first, end] : runs) r.push_back({base + first * texel_bytes, (end - first) * texel_bytes});
      return r;
    };
    // Copies packed ranges of a per-texel array of `texel_bytes` per texel, `layers` of them one
    // after another (device: texel_count texels per layer; host: host_texels), to their host places.
    auto place = [&](char* host, size_t texel_bytes, int layers, const char* packed_bytes) {
      for (int k = 0; k < layers; ++k)
        for (size_t j = 0; j < runs.size(); ++j) {
          const size_t bytes = (runs[j].second - runs[j].first) * texel_bytes;
          std::memcpy(host + (size_t(k) * host_texels + to[j]) * texel_bytes, packed_bytes, bytes);
          packed_bytes += bytes;
        }
    };
    // Read through the staging mappings (a million texels' sums are ~50 MB: no host copy in between).
    std::vector<ByteRange> layers;
    for (int k = 0; k < a.recorded; ++k)
      for (const ByteRange& r : ranges(24, size_t(k) * texel_count * 24)) layers.push_back(r);
    context.read_back_ranges(sums.bounce_sums, layers, [&](const char* bytes) {
      place(reinterpret_cast<char*>(estimate.bounces.data()), 24, a.recorded, bytes);
    }, staging);
    if (a.light_layers > 0) {  // after the recorded layers in the same buffer
      std::vector<ByteRange> lights;
      for (int k = 0; k < a.light_layers; ++k)
        for (const ByteRange& r : ranges(24, size_t(a.recorded + k) * texel_count * 24)) lights.push_back(r);
      context.read_back_ranges(sums.bounce_sums, lights, [&](const char* bytes) {
        place(reinterpret_cast<char*>(estimate.light_sums.data()), 24, a.light_layers, bytes);
      }, staging);
    }
    context.read_back_ranges(sums.sums, ranges(48, 0), [&](const char* bytes) {
      const double* sums = reinterpret_cast<const double*>(bytes);
      for (size_t k = 0; k < runs.size(); ++k)
        for (size_t i = to[k], end = to[k] + runs[k].second - runs[k].first; i < end; ++i, sums += 6) {
          TexelAccumulator& t = estimate.texels[i];
          for (int c = 0; c < 3; ++c) {
            t.total[c] = sums[c];
            t.total_squared[c] = sums[3 + c];
            t.direct[c] = estimate.bounces[i * 3 + size_t(c)];  // layer 0 is the direct light
          }
        }
    }, staging);
    context.read_back_ranges(sums.samples, ranges(4, 0), [&](const char* bytes) {
      const uint32_t* samples = reinterpret_cast<const uint32_t*>(bytes);
      for (size_t k = 0; k < runs.size(); ++k)
        for (size_t i = to[k], end = to[k] + runs[k].second - runs[k].first; i < end; ++i) estimate.texels[i].samples = *samples++;
    }, staging);
    if (a.directional)  // L1 sums: 9 doubles per texel after the 6 of every texel
      context.read_back_ranges(sums.sums, ranges(72, texel_count * 48), [&](const char* bytes) {
        place(reinterpret_cast<char*>(estimate.sh1.data()), 72, 1, bytes);
      }, staging);
  }
  estimate.rays = a.totals.rays();
  estimate.nonfinite_samples = a.totals.nonfinite;
  estimate.guided_vertices = a.totals.guided_vertices;
  estimate.light_subpaths = a.totals.light_subpaths;
  estimate.light_subpath_vertices = a.totals.light_subpath_vertices;
  estimate.seconds = a.seconds;
  return estimate;
}

std::vector<uint32_t> LightmapDriver::unconverged(const std::vector<uint32_t>& work_list, size_t texel_count, double target) {
  const TexelAccumulators& texels = runner_.buffers().texels;
  std::vector<double> sums(texel_count * 6);
  std::vector<uint32_t> samples(texel_count);
  runner_.context().download(texels.sums, sums.data(), sums.size() * 8);
  runner_.context().download(texels.samples, samples.data(), samples.size() * 4);
  std::vector<uint32_t> still;
  for (uint32_t i : work_list) {
    LightmapEstimate one;  // the reference's test (estimates.h)
    one.texels.resize(1);
    for (int c = 0; c < 3; ++c)
      one.texels[0].total[c] = sums[i * 6 + size_t(c)], one.texels[0].total_squared[c] = sums[i * 6 + 3 + size_t(c)];
    one.texels[0].samples = samples[i];
    if (!one.relative_error_below(0, target)) still.push_back(i);
  }
  return still;
}

bool LightmapDriver::auto_measures_light_subpaths(const IntegratorSettings& settings) const {
  if (settings.guiding_auto_candidate == AutoGuidingCandidate::Grid || !guiding_scene_.lighting) return false;
  const bool starts = light_subpaths_start_anywhere(light_subpath_start(*guiding_scene_.lighting));
  return starts && (settings.guiding_auto_candidate == AutoGuidingCandidate::LightSubpaths || light_subpath_pilots_fit(settings.spp));
}

LightmapEstimate LightmapDriver::bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) {
  // --guiding auto with no candidate for this bake (below): the unguided bake, bit for bit, no pilot.
  if (settings.guiding == GuidingMode::Auto && settings.guiding_auto_candidate != AutoGuidingCandidate::Grid &&
      !auto_measures_light_subpaths(settings)) {
    IntegratorSettings unguided = settings;
    unguided.guiding = GuidingMode::Off;
    LightmapEstimate estimate = bake(gbuffer, unguided);
    estimate.guiding_auto = estimate.guiding_auto_unmeasured = true;
    return estimate;
  }
  const auto start_time = Clock::now();
  progressive_.reset();  // the buffers are this bake's now
  runner_.statistics().clear();
  // Split over processes (core/work_share.h): this rank's device runs its interleaved blocks of the
  // texels through the work list (global indices, so the same random streams); the sums are
  // gathered onto rank 0 once at the end. Every rank follows every pass (rank 0 decides them), work or not.
  WorkShare* share = distributed(settings.work_share);
  InterleavedSplit split;
  split.items = gbuffer.texels.size();
  split.ranks = share ? share->ranks() : 1;
  const Runs own_runs = share ? split.runs_of(share->rank()) : Runs{{0, split.items}};
  Accumulation a;
  prepare(gbuffer, settings, a, &own_runs);
  if (a.texel_count == 0) return download(a);

  const uint32_t spp_limit = settings.spp == 0 ? std::numeric_limits<uint32_t>::max() : settings.spp;
  // Grid guiding (guide_buffer.h): the CPU reference's cache and its passes. Built inside the timed
  // bake, as on the CPU: guided results are measured with the cost of their guiding data.
  std::unique_ptr<GridGuidingCache> guide;
  std::optional<GuideBuffer> guide_buffer;
  // --guiding auto (core/guiding_choice.h, as on the CPU): the grid guide learns during a pilot in
  // which a hashed quarter of the texels take guided and unguided halves; the device sums each
  // strategy's samples per texel (gpu_layout.h kGuidingAuto), read back once when the pilot is
  // complete; GuidingChoice decides per region, and the texels' verdicts go back as strategy words.
  // Its candidate (AutoGuidingCandidate), as on the CPU: light subpaths where a light starts them
  // and the bake is long enough for their pilot (--spp of kLightSubpathPilots pilots, or unlimited:
  // under --time the pass rate decides below), or where they are named. A "guided" sample is then
  // one whose path connects to the batch's pool (gpu_layout.h kGuidingAutoSubpaths); the grid's
  // records are the regions and the guide buffer carries the strategy words and sums only.
  // Unlike the CPU, the scene's candidate is never grid guiding here: on the GPU its learning
  // samples cost 1.7-2.6x an unguided one and it lost at equal time on every scene measured
  // (bench/results/guiding-gpu.md), so its pilot only cost time (an H100 at 256 spp: 3-4x the
  // unguided bake's, every region then unguided: bench/results/guiding-auto-gpu.md). A bake that
  // light subpaths do not fit measures nothing and is the unguided one; grid guiding is measured
  // only where named (AutoGuidingCandidate::Grid: bake --guiding auto --light-paths off).
  const bool auto_guiding = settings.guiding == GuidingMode::Auto;
  const bool auto_light_subpaths = auto_guiding && auto_measures_light_subpaths(settings);
  // Under --time the light-subpath candidate's setup (the pools, the regions, the choice, the words
  // and their upload: 0.05-0.08 s at 0.4-1 M texels on an H100 host) waits for the pass rate's check
  // below: a bake that then abandons the candidate never pays it, and until then the bake is the
  // unguided one (the pilot's first half is all unguided samples at their own indices anyway). The
  // pilot's statistics then start where the setup is made. Not with emitter guiding, whose section
  // follows the auto sections in the guide buffer.
  const bool defer_auto_setup = auto_light_subpaths && settings.time_budget_seconds > 0 && !settings.emitter_guiding &&
                                !settings.light_subpaths;
  double auto_setup_seconds = 0;
  const uint32_t light_subpath_pilot = GuidingChoice::pilot_for(settings.spp, kLightSubpathPilotSamples);
  std::unique_ptr<GuidingChoice> choice;
  std::vector<uint32_t> auto_words;
  auto set_up_guide = [&](uint32_t statistics_from_light_subpaths) {
    const auto setup_start = Clock::now();
    if (settings.light_subpaths || auto_light_subpaths) {
      IntegratorSettings pool_settings = settings;
      pool_settings.light_subpaths = true;
      make_light_pools(a, pool_settings);
    }
    if (settings.guiding == GuidingMode::Grid || auto_guiding) {
      GridGuidingConfig config;
      config.mix = settings.guiding_mix;
      config.cells_on_longest_axis = settings.guiding_grid_cells;
      guide = std::make_unique<GridGuidingCache>(guiding_scene_.bounds_lo, guiding_scene_.bounds_hi,
                                                 guiding_scene_.reference_radiance, gbuffer, config);
      // Light subpaths as auto's candidate: the grid's records are only the regions, its tables unread.
      if (auto_light_subpaths) guide_buffer.emplace();
      else guide_buffer.emplace(*guide);
      if (auto_guiding) {
        // Regions: the guide's records (grid cell x normal class), texels without one in one more (as on the CPU).
        const uint32_t pilot =
            GuidingChoice::pilot_for(settings.spp, auto_light_subpaths ? kLightSubpathPilotSamples : GridGuidingCache::kLearningSamples);
        // On all host cores: the lookups are independent, and at a million texels this is inside the timed bake.
        std::vector<uint32_t> region(a.texel_count);
        for_each_chunk(a.texel_count, [&](size_t begin, size_t end) {
          for (size_t i = begin; i < end; ++i) {
            const uint32_t r = guide->record_of(gbuffer.texels[i].position, gbuffer.texels[i].shading_normal);
            region[i] = r == GridGuidingCache::kNoRecord ? guide->record_count() : r;
          }
        });
        // Light subpaths: statistics from the first sample (nothing learns; from the deferred setup's
        // sample under --time), the connected half of the pilot second, so that a short bake can
        // abandon them unmeasured (as on the CPU).
        const uint32_t statistics_from = auto_light_subpaths ? statistics_from_light_subpaths : pilot / 4;
        // Its sums are the device's (reduce.comp), read back once at the pilot's end.
        choice = std::make_unique<GuidingChoice>(std::move(region), guide->record_count() + 1, pilot, statistics_from, settings.seed,
                                                 kPilotMeasuringShare, false);
        choice->set_guided_vertex_cost(kGuidedVertexCostInRaysVulkan);
        if (auto_light_subpaths) choice->set_candidate_half_second(), choice->set_guided_cost_factor(kConnectedSampleCostFactorVulkan);
        auto_words = strategy_words(*choice, a.texel_count);
        guide_buffer->add_auto_sections(auto_words, pilot, statistics_from);
      }
      guide_buffer->upload(runner_);
    }
    auto_setup_seconds = std::chrono::duration<double>(Clock::now() - setup_start).count();
  };
  if (share && (settings.guiding == GuidingMode::Grid || auto_guiding))  // before any pass, deferred setup or not
    throw std::invalid_argument("Vulkan backend: guiding runs in one process only, not under mpirun with several ranks");
  if (!defer_auto_setup) set_up_guide(0);
  // SVO guiding (svo_guide_buffer.h): the CPU reference's fields and schedule. The first pass is
  // unguided (no bins yet) unless the octree holds exitance; the passes that reach 1, 2, 4, ...
  // samples per texel count their vertices on the device, then the host rebuilds the fields from the
  // running lightmap and those counts and uploads them.
  std::unique_ptr<SvoGuidingFields> svo_guide;
  std::optional<SvoGuideBuffer> svo_buffer;
  uint32_t svo_next_rebuild = 1;
  if (settings.guiding == GuidingMode::Svo) {
    if (share) throw std::invalid_argument("Vulkan backend: guiding runs in one process only, not under mpirun with several ranks");
    if (!settings.guiding_octree)
      throw std::invalid_argument("Vulkan backend: --guiding svo needs the bake's sparse voxel octree (not --voxel-resolution none)");
    if (!guiding_scene_.lighting) throw std::logic_error("Vulkan backend: SVO guiding without the integrator's scene");
    svo_guide = std::make_unique<SvoGuidingFields>(*guiding_scene_.lighting, *settings.guiding_octree, gbuffer,
                                                   svo_guiding_config(settings));
    if (svo_guide->seeded()) svo_guide->rebuild(nullptr, 0, settings.seed);
    svo_buffer.emplace(*svo_guide);
    svo_buffer->upload(runner_);
  }
  // Emitter guiding (emitter_guide_buffer.h): the CPU reference's cache, its learning schedule and
  // its fold between passes; its section follows the other guide's words in the guide buffer.
  std::unique_ptr<EmitterGuidingCache> emitter_guide;
  std::optional<EmitterGuideBuffer> emitter_buffer;
  LightmapEstimate::EmitterGuidingReport emitter_costs;  // its host seconds (setup, folds)
  const auto emitter_setup_start = Clock::now();
  if (settings.emitter_guiding) {
    if (share) throw std::invalid_argument("Vulkan backend: --emitter-guiding runs in one process only, not under mpirun with several ranks");
    if (svo_guide)
      throw std::invalid_argument("Vulkan backend: --emitter-guiding on with --guiding svo is implemented on the CPU backend only");
    // The host's cache (19-21 ms at a million texels on an H100's host) is made on a thread while the
    // device allocates the learning's path state (64 B per path slot; with the guide buffer's growth
    // 30-37 ms: bench/results/emitter-guiding.md), which does not depend on it.
    std::future<std::unique_ptr<EmitterGuidingCache>> made = std::async(std::launch::async, [&] {
      return emitter_guide_for_device(guiding_scene_.lighting, runner_.scene(), gbuffer, settings);
    });
    // A grown buffer replaces the one the descriptors name: they follow it at once.
    const LightingScene* lighting = guiding_scene_.lighting.get();
    if (lighting && EmitterGuidingCache::guides(*lighting) && runner_.buffers().paths.reserve_emitter_learning(runner_.context(), settings.light_subpaths))
      runner_.bind_buffers();
    emitter_guide = made.get();
  }
  if (emitter_guide) {
    Context& context = runner_.context();
    WavefrontBuffers& buffers = runner_.buffers();
    emitter_buffer.emplace(*emitter_guide, guide_buffer ? guide_buffer->bytes() / 4 : kGuideHeaderWords);
    const size_t bytes = emitter_buffer->end_word() * 4;
    if (uint64_t(bytes) > context.properties().limits.maxStorageBufferRange)
      throw std::runtime_error("Vulkan backend: --emitter-guiding on: the guide buffer (" + std::to_string(bytes) +
                               " bytes) passes the device's largest storage buffer (use fewer --guiding-grid-cells or "
                               "--emitter-guiding-patches)");
    if (buffers.probes.sh_sums.size() < bytes) {
      buffers.probes.reserve_bytes(context, bytes);  // a new buffer: the other guide's words again
      if (guide_buffer) guide_buffer->upload(runner_);
      runner_.bind_buffers();
    }
    if (!guide_buffer) {  // no other guide: a header of zeros (no locator, no auto sections)
      const std::vector<uint32_t> header(kGuideHeaderWords, 0u);
      context.upload(buffers.probes.sh_sums, header.data(), header.size() * 4);
    }
    emitter_buffer->upload(runner_);
    a.params.emitter_guide = emitter_buffer->params_offset();
    emitter_costs.setup_seconds = std::chrono::duration<double>(Clock::now() - emitter_setup_start).count();
  }
  PassPolicy policy;
  // Untimed: as many samples per batch as fill the work items; a budget or target error: ramped passes.
  // Guided: ramped while learning, so the table swaps after the same samples as the CPU's (1, 2, 3,
  // 4, 8, ... 64); then, untimed, the largest passes (the frozen table makes pass sizes irrelevant).
  policy.largest_pass = uint32_t(std::max<size_t>(1, a.max_work / std::min(a.texel_count, a.max_work)));
  policy.ramp = settings.time_budget_seconds > 0 || settings.target_relative_error > 0;
  // Auto: ramped through its pilot only (the table freezes there; its last pass ends at the pilot).
  if (guide && !policy.ramp) policy.ramp = true, policy.ramp_below = choice ? choice->pilot() : GridGuidingCache::kLearningSamples;
  // SVO: ramped throughout, as on the CPU, so its rebuilds (1, 2, 4, ... spp) end passes of the same sizes.
  if (svo_guide) policy.ramp = true, policy.ramp_below = PassPolicy{}.ramp_below;
  // Emitter guiding: ramped while every vertex learns, in passes that double as the CPU's do, and
  // folded where EmitterGuidingCache::folds_after says (1, 2, 3, 4, 8, 16, 32, 64 samples: the
  // CPU's points, whatever the work items cut a pass to); after that passes as large as fill the
  // work items, under a time budget too (later samples learn only where a record samples what it
  // learned, and fold after each pass; the budget still cuts the last pass). With grid guiding
  // beside it, grid's ramp applies.
  if (emitter_guide && (!guide || !policy.ramp)) policy.ramp = true, policy.ramp_below = EmitterGuidingCache::kEveryLearningSamples;
  if (settings.emitter_guiding) policy.doubling_below = EmitterGuidingCache::kEveryLearningSamples;
  PassScheduler passes(settings, policy);
  // The estimate is hundreds of MB at millions of texels: a thread allocates it and touches its
  // pages, and makes the read-back's pinned staging buffer, while the host waits on the device's
  // passes. Under a split it is whole on rank 0 alone, and holds just their own texels on the other
  // ranks (which send them).
  const bool whole_here = !share || share->rank() == 0;
  std::future<ReadBackSpace> space = std::async(std::launch::async, &LightmapDriver::read_back_space, this,
                                                whole_here ? a.texel_count : a.work_list.size(), a.work_list.size(), a.recorded,
                                                a.directional, a.light_layers);
  // Once no texel connects (the candidate abandoned, or no region kept connections) the pools go: the
  // batches then have the unguided bake's layout and cost (before, an abandoned 1 s bake of the Cornell
  // room at 64 texels/m still traced a pool per batch and took half the unguided samples on an H100).
  auto drop_unread_pools = [&] {
    if (auto_light_subpaths && !settings.light_subpaths && choice->texels_guided() == 0) drop_light_pools(a);
  };
  double elapsed_at_4 = -1;   // the budget's seconds when 4 samples per texel were done
  uint32_t abandoned_at = 0;  // samples per texel when the light-subpath candidate was abandoned
  uint32_t first = 0, pass = 0;
  while ((share || !a.work_list.empty()) && passes.next_pass(first, pass)) {
    const auto pass_start = Clock::now();
    // Auto: the guide learns during the pilot only; the pilot's passes record the strategy sums; after
    // the choice only its guided texels' samples look the guide up (none at all: no guide lookup,
    // but the strategy words still index each texel's unguided sequence where its pilot left it).
    const bool learning = guide && !auto_light_subpaths && first < (choice ? choice->pilot() : GridGuidingCache::kLearningSamples) &&
                          (!choice || !choice->decided());
    if (guide) a.params.guiding = auto_light_subpaths ? kGuidingAutoSubpaths : kGuidingSample | (learning ? kGuidingLearn : 0u);
    if (choice) a.params.guiding |= kGuidingAuto | (choice->decided() ? 0u : kGuidingAutoRecord);
    if (choice && choice->decided() && choice->texels_guided() == 0)
      a.params.guiding = kGuidingAuto | (auto_light_subpaths ? kGuidingAutoSubpaths : 0u);  // no path connects either
    // Light subpaths as the candidate: the pool serves the pass's connecting samples only.
    if (auto_light_subpaths && a.light_pools) a.light_pools->set_connected_share(choice->candidate_share(first, pass));
    if (!a.work_list.empty()) {
      const size_t chunk = std::min(a.work_list.size(), a.max_work);
      pass = std::min<uint32_t>(pass, uint32_t(std::max<size_t>(1, a.max_work / chunk)));
      if (svo_guide) a.params.guiding = kGuidingSample | (first + pass >= svo_next_rebuild ? kGuidingCount : 0u);
      run_pass(a, first, pass);
      if (share) share->work.texel_samples += uint64_t(a.work_list.size()) * pass;
    }
    if (learning && settings.guide_fold_on_host) {
      guide_buffer->fold_learning_on_host(runner_, *guide);
    } else if (learning) {  // this pass's learning is the next pass's table, folded on the device
      if (!guide_fold_) guide_fold_ = std::make_unique<GuideFoldKernel>(runner_.context(), GuideFold::Grid);
      guide_buffer->fold_learning(runner_, *guide_fold_);
    }
    if (emitter_buffer && a.params.emitter_guide != 0u && EmitterGuidingCache::folds_after(first + pass)) {
      const auto fold_start = Clock::now();
      bool active = false;
      if (settings.guide_fold_on_host) {
        active = emitter_buffer->fold_learning_on_host(runner_, *emitter_guide, first + pass);
      } else {  // folded on the device: the next pass reads the new tables
        if (!emitter_fold_) emitter_fold_ = std::make_unique<GuideFoldKernel>(runner_.context(), GuideFold::Emitter);
        active = emitter_buffer->fold_learning(runner_, *emitter_fold_, *emitter_guide, first + pass);
      }
      if (!active) a.params.emitter_guide = 0;  // no record gains: the default sampling from here, as on the CPU
      emitter_costs.fold_seconds += std::chrono::duration<double>(Clock::now() - fold_start).count();
      ++emitter_costs.folds;
    }
    // Light subpaths as auto's candidate under a time budget: while no candidate sample has been taken
    // (the pilot's first half), a bake whose pass rate promises fewer than kLightSubpathPilots pilots
    // abandons the candidate and runs on as the unguided bake (kLightSubpathPilots says why; as on the
    // CPU). The rate is that of the passes after the first 4 samples, from 16 on: the ramp's first
    // passes, of one sample each, carry a pass's fixed costs (from them an H100 promised the Cornell
    // room at 64 texels/m 400 samples in 4 s, where it took 2 900-3 900).
    const uint32_t done_here = first + pass;
    if (auto_light_subpaths && done_here == 4) elapsed_at_4 = passes.elapsed_seconds();
    const bool undecided = choice ? auto_light_subpaths && !choice->decided() : defer_auto_setup && abandoned_at == 0;
    if (undecided && settings.time_budget_seconds > 0 && elapsed_at_4 >= 0 && done_here >= std::min(16u, light_subpath_pilot / 2) &&
        done_here > 4 && done_here <= light_subpath_pilot / 2) {
      const double elapsed = passes.elapsed_seconds();
      const double per_sample = (elapsed - elapsed_at_4) / double(done_here - 4);
      if (!light_subpath_pilots_promised(done_here, per_sample, settings.time_budget_seconds - elapsed, light_subpath_pilot)) {
        abandoned_at = done_here;
        if (choice) {
          choice->abandon();
          auto_words = strategy_words(*choice, a.texel_count);
          guide_buffer->upload_auto_words(runner_, auto_words);
          drop_unread_pools();
        }
      } else if (!choice) {
        set_up_guide(done_here);  // the candidate will be measured: set up now, its statistics from here
      }
    }
    if (choice && !choice->decided() && first + pass >= choice->pilot()) {  // the pilot is complete on every texel
      import_strategy_sums(guide_buffer->download_auto_sums(runner_), *choice);
      // A connected sample's share of the pools: their rays per subpath x subpaths per sample.
      if (auto_light_subpaths && a.totals.light_subpaths > 0)
        choice->set_guided_sample_cost(double(a.totals.light_subpath_rays) / double(a.totals.light_subpaths) *
                                       settings.light_subpaths_per_sample);
      choice->decide();
      auto_words = strategy_words(*choice, a.texel_count);
      guide_buffer->upload_auto_words(runner_, auto_words);
      drop_unread_pools();
    }
    if (svo_guide && (a.params.guiding & kGuidingCount) != 0u) {  // this pass counted: rebuild the fields
      svo_buffer->import_counts(runner_, *svo_guide);
      const LightmapEstimate running = download(a);
      svo_guide->rebuild(&running, double(pass), settings.seed);
      svo_buffer->repack(runner_, *svo_guide);
      svo_next_rebuild = 2 * (first + pass);
    }
    const uint32_t done = first + pass;
    if (settings.target_relative_error > 0 && done >= 16 && done < spp_limit) {
      std::vector<uint32_t> still = unconverged(a.work_list, a.texel_count, settings.target_relative_error);
      if (still.size() != a.work_list.size()) {
        a.work_list = std::move(still);
        if (!a.work_list.empty())
          runner_.context().upload(runner_.buffers().items.batch_items, a.work_list.data(), a.work_list.size() * 4);
      }
    }
    bool all_converged = a.work_list.empty();
    if (share) {
      share->work.seconds += std::chrono::duration<double>(Clock::now() - pass_start).count();
      all_converged = share->sum(a.work_list.size()) == 0;
    }
    passes.finish_pass(a.totals.rays(), all_converged);
  }
  a.seconds = std::chrono::duration<double>(Clock::now() - start_time).count();
  runner_.record_statistics(a.totals, kTexelBatch);
  // Under a split only this rank's texels are read back: in place on rank 0, which gathers the
  // others' below; packed on the others, which send them.
  LightmapEstimate estimate = download(a, share ? &own_runs : nullptr, space.get(), /*packed=*/!whole_here);
  // Without a choice under a deferred setup: the bake ended before the rate's check, or abandoned there.
  if (choice || defer_auto_setup) {
    estimate.guiding_auto = true;
    estimate.guiding_auto_light_subpaths = auto_light_subpaths;
    estimate.guiding_auto_pilot = choice ? choice->pilot() : light_subpath_pilot;
    estimate.guiding_auto_abandoned_at = abandoned_at;
    estimate.guiding_auto_setup_seconds = auto_setup_seconds;
  }
  if (choice) {
    estimate.guiding_auto_cost_factor = choice->guided_cost_factor();
    if (choice->decided() && !choice->abandoned()) estimate.guiding_regions = choice->regions(), estimate.guiding_scene = choice->scene();
  }
  if (guide && !auto_light_subpaths && settings.inspect_guiding) {
    if (!settings.guide_fold_on_host) guide_buffer->download_tables(runner_, *guide);
    settings.inspect_guiding(*guide);
  }
  if (svo_guide && settings.inspect_svo_guiding) settings.inspect_svo_guiding(*svo_guide);
  if (emitter_guide) {
    estimate.emitter_guiding = emitter_costs;  // the host's seconds; report() fills in the cache's part
    emitter_buffer->report(runner_, *emitter_guide, settings, estimate.emitter_guiding);
  }
  if (settings.work_share) settings.work_share->work.rays += estimate.rays;
  if (share) {
    // Rank 0 alone writes the bundle: the per-texel sums go to it, and the other ranks keep none.
    const size_t layer_texels = estimate.texels.size();
    gather_interleaved_to_root(*share, estimate.texels.data(), 1, split);
    for (int k = 0; k < estimate.recorded_bounces; ++k)
      gather_interleaved_to_root(*share, estimate.bounces.data() + size_t(k) * layer_texels * 3, 3, split);
    if (!estimate.sh1.empty()) gather_interleaved_to_root(*share, estimate.sh1.data(), 9, split);
    if (!whole_here) estimate.texels = {}, estimate.bounces = {}, estimate.sh1 = {};
    estimate.rays = share->sum(estimate.rays);
    estimate.nonfinite_samples = share->sum(estimate.nonfinite_samples);
  } else if (settings.work_share) {
    for (const TexelAccumulator& t : estimate.texels) settings.work_share->work.texel_samples += t.samples;
    settings.work_share->work.seconds += estimate.seconds;
  }
  return estimate;
}

void LightmapDriver::start(const TexelGBuffer& gbuffer, const IntegratorSettings& settings, uint32_t changed_light_pairs,
                           bool texels_as_before, bool accumulation_cleared, const std::vector<uint32_t>& changed_light_layers) {
  const auto start_time = Clock::now();
  std::optional<Accumulation> before = std::move(progressive_);
  progressive_.reset();
  runner_.statistics().clear();
  Accumulation a;
  const bool reuse = texels_as_before && before && before->texel_count == gbuffer.texels.size() &&
                     before->start_points.size() == gbuffer.texels.size();
  prepare(gbuffer, settings, a, nullptr, reuse ? &*before : nullptr, accumulation_cleared);
  a.params.changed_light_pairs = changed_light_pairs;
  // A change estimate's contributions go to the edited lights' layers (GpuParams::changed_light_layers).
  for (size_t k = 0; k < kMaxChangedLightPairs; ++k)
    a.params.changed_light_layers[k] = k < changed_light_layers.size() ? changed_light_layers[k] : 0;
  // Light subpaths, a pool per batch as in bake(); not for a change estimate, whose paths add only
  // the edited lights' direct light (path.glsl light_subpaths_on), so a pool would go unread.
  if (settings.light_subpaths && changed_light_pairs == 0) make_light_pools(a, settings);
  a.seconds = std::chrono::duration<double>(Clock::now() - start_time).count();
  progressive_ = std::move(a);
}

void LightmapDriver::scene_changed() {
  if (!progressive_) return;
  GpuParams& p = progressive_->params;
  const GpuParams scene = runner_.bake_params(IntegratorSettings{}, p.recorded, p.item_count_total);
  p.sky = scene.sky;
  p.scene_extent = scene.scene_extent;
  p.emitter_count = scene.emitter_count;
  p.emitter_inverse_power = scene.emitter_inverse_power;
  p.punctual_count = scene.punctual_count;
  p.surface_flags = scene.surface_flags;
  p.environment_width = scene.environment_width;
  p.environment_height = scene.environment_height;
  p.shadow_slots = scene.shadow_slots;
  p.traversal_steps = scene.traversal_steps;
  // The subpaths' start probabilities follow the lights' power: made again from the edited scene
  // (they also set the shadow slots the connection takes). Samples before keep their own, each
  // unbiased for the lights they were traced under.
  if (progressive_->light_pools) make_light_pools(*progressive_, progressive_->light_pool_settings);
}

void LightmapDriver::set_light_subpaths(const IntegratorSettings& settings) {
  if (!progressive_) return;
  Accumulation& a = *progressive_;
  // A change estimate's paths add only the edited lights' direct light: no pool (as start()).
  if (settings.light_subpaths && a.params.changed_light_pairs == 0) {
    make_light_pools(a, settings);
    return;
  }
  drop_light_pools(a);
}

void LightmapDriver::drop_light_pools(Accumulation& a) {
  if (!a.light_pools) return;
  a.light_pools.reset();
  a.params.light_subpaths = 0;  // before_batch set it for the pools' last batch
  a.params.shadow_slots = runner_.bake_params(IntegratorSettings{}, a.params.recorded, a.params.item_count_total).shadow_slots;
}

void LightmapDriver::update_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& texels) {
  if (!progressive_ || texels.empty()) return;
  Accumulation& a = *progressive_;
  if (a.start_points.size() != gbuffer.texels.size()) return;  // a whole run's accumulation: start() uploads all
  for (uint32_t i : texels)
    if (i >= a.start_points.size()) throw std::out_of_range("Vulkan backend: texel " + std::to_string(i) + " of " + std::to_string(a.start_points.size()));
  for (uint32_t i : texels) a.start_points[i] = texel_start_point(gbuffer.texels[i]);
  WavefrontBuffers& buffers = runner_.buffers();
  if (buffers.items.owner != WorkItems::Owner::Texels) return;  // uploaded whole before the next pass
  constexpr size_t kPoint = sizeof(GpuSurfacePoint);
  std::vector<uint32_t> sorted = texels;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  // The host's start points fill the gaps between joined runs; staged now, copied at the start of
  // the next submission (an edit's publish).
  runner_.context().write_ranges_at_next_submission(
      {Context::RangeWrite::mirrored(buffers.items.start_points, a.start_points.data(), byte_ranges(record_runs(sorted, kPoint), kPoint))});
}

uint64_t LightmapDriver::add_samples(uint32_t samples) {
  if (!progressive_) throw std::logic_error("Vulkan backend: add_samples before start_progressive");
  Accumulation& a = *progressive_;
  std::vector<uint32_t> all(a.texel_count);
  for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
  const uint64_t rays = add_samples_to(all, a.next_sample, samples);
  a.next_sample += samples;
  return rays;
}

uint64_t LightmapDriver::add_samples_to(const std::vector<uint32_t>& texels, uint32_t first_sample, uint32_t samples) {
  if (!progressive_) throw std::logic_error("Vulkan backend: add_samples before start_progressive");
  Accumulation& a = *progressive_;
  if (samples == 0 || texels.empty()) return 0;
  if (uint64_t(first_sample) + samples > std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument("Vulkan backend: more than 2^32 - 1 samples per texel");
  for (uint32_t i : texels)
    if (i >= a.texel_count) throw std::out_of_range("Vulkan backend: texel " + std::to_string(i) + " of " + std::to_string(a.texel_count));
  const auto start_time = Clock::now();
  const uint64_t rays_before = a.totals.rays();
  runner_.bind_buffers();  // a probe bake in between may have grown (reallocated) a buffer
  if (runner_.buffers().items.owner != WorkItems::Owner::Texels) {
    upload_items(a);
  }
  if (a.work_list != texels) {
    a.work_list = texels;
    runner_.context().upload(runner_.buffers().items.batch_items, a.work_list.data(), a.work_list.size() * 4);
  }
  // At most as many samples per batch as fill the work items.
  const uint32_t largest = uint32_t(std::max<size_t>(1, a.max_work / std::min(a.work_list.size(), a.max_work)));
  uint32_t next = first_sample;
  for (uint32_t left = samples; left > 0;) {
    const uint32_t pass = std::min(left, largest);
    run_pass(a, next, pass);
    next += pass;
    left -= pass;
  }
  a.seconds += std::chrono::duration<double>(Clock::now() - start_time).count();
  runner_.record_statistics(a.totals, kTexelBatch);
  return a.totals.rays() - rays_before;
}

LightmapEstimate LightmapDriver::read() {
  if (!progressive_) throw std::logic_error("Vulkan backend: progressive_estimate before start_progressive");
  return download(*progressive_);
}

LightmapEstimate LightmapDriver::read(const DeviceLightmap& lightmap) {
  // The shape, with the progressive accumulation's rays, seconds and counters (what is published
  // was composed from it).
  Accumulation a;
  if (progressive_) a.totals = progressive_->totals, a.seconds = progressive_->seconds;
  a.texel_count = lightmap.texels;
  a.recorded = lightmap.layers;
  a.light_layers = lightmap.light_layers;
  a.directional = lightmap.directional;
  return download(a, nullptr, {}, false, &lightmap.sums);
}

LightmapDriver::Shape LightmapDriver::shape() const {
  if (!progressive_) throw std::logic_error("Vulkan backend: publishing before start_progressive");
  return {progressive_->texel_count, progressive_->recorded, progressive_->directional, progressive_->light_layers};
}

}  // namespace exitance::vulkan
