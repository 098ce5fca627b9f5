#include "light_subpath_pools.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/core/light_subpath_start.h"

namespace exitance::vulkan {
namespace {

// Subpaths in the pool of a batch of `work` samples, `per_sample` each (the CPU's bounds, up to the
// binding's kLightPoolMostPaths).
uint32_t pool_paths(double work, double per_sample) {
  return uint32_t(std::clamp(std::ceil(work * per_sample), double(kFewestLightSubpathsPerPool), double(kLightPoolMostPaths)));
}

// Pool vertices reserved per subpath at first: indoor scenes keep 2-5 (ajar_room 2.8, the building
// 5.1 on an H100); a pool that needs more grows the binding for the next batch.
constexpr uint64_t kVerticesPerPath = 16;

}  // namespace

LightSubpathPools::LightSubpathPools(WavefrontBatchRunner& runner, const LightingScene& lighting,
                                     const IntegratorSettings& settings, size_t max_work, GpuParams& params)
    : runner_(runner) {
  const LightSubpathSampling start = light_subpath_start(lighting);
  if (!light_subpaths_start_anywhere(start) || max_work == 0) return;  // no light starts one: path tracing
  per_sample_ = settings.light_subpaths_per_sample;
  params.light_subpath_start = Vec4(start.area_probability, start.punctual_scale, start.sky_probability, start.disk_density);
  params.light_subpath_sphere = Vec4((lighting.bounds_lo + lighting.bounds_hi) * 0.5f, scene_radius(lighting));
  params.light_subpath_depth = light_subpath_depth(settings);
  const bool environment = runner_.scene().environment_width() > 0;
  params.shadow_slots = environment ? kShadowSlotsWithEnvironmentAndConnection : kShadowSlotsWithConnection;
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  const uint64_t vertices = uint64_t(pool_paths(double(max_work), per_sample_)) * kVerticesPerPath;
  const bool grew = buffers.paths.reserve_light_subpaths(context, environment, settings.emitter_guiding);
  if (buffers.light_pool.reserve(context, std::min(vertices, most_vertices())) || grew) runner_.bind_buffers();
  params.light_subpath_capacity = buffers.light_pool.capacity();
}

void LightSubpathPools::before_batch(GpuParams& params, double work) const {
  // A share of 0 still traces the fewest subpaths: the batch's paths keep their connection slot's layout.
  params.light_subpaths = active() ? pool_paths(work * connected_share_, per_sample_) : 0u;
}

void LightSubpathPools::after_batch(const BatchTotals& totals, GpuParams& params) {
  if (!active() || totals.pool_vertices_needed <= params.light_subpath_capacity || params.light_subpath_capacity >= most_vertices())
    return;
  const uint64_t wanted = std::min(uint64_t(totals.pool_vertices_needed) * 2, most_vertices());
  if (runner_.buffers().light_pool.reserve(runner_.context(), wanted)) runner_.bind_buffers();
  params.light_subpath_capacity = runner_.buffers().light_pool.capacity();
}

uint64_t LightSubpathPools::most_vertices() const {
  const uint64_t words = uint64_t(runner_.context().properties().limits.maxStorageBufferRange) / 4;
  return words > kLightPoolVertexWord ? (words - kLightPoolVertexWord) / kLightVertexWords : 0;
}

}  // namespace exitance::vulkan
