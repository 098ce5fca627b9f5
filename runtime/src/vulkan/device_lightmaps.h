// Lightmap estimates kept in device memory for the runtime's publishing (issue 32): what each texel
// showed before the last edit, a change estimate's base, and what it publishes now, each in the
// layout of the wavefront's texel sums, composed from the progressive accumulation on the device by
// shaders/wavefront/publish.comp (exitance/common/publishing_rule.h: the rule
// refresh/published_estimate.cpp applies on the host). An edit then keeps what was shown with one
// dispatch instead of a read-back of the whole lightmap.
#pragma once
#include <array>
#include <cstdint>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "compute_kernel.h"
#include "vulkan_context.h"
#include "wavefront_buffers.h"

namespace exitance {

// Per texel: 6 doubles of sums (+ 9 of L1 when directional), 3 doubles per recorded layer, the
// sample count (LightmapEstimate's fields, layer 0 being the direct light). The light layers' sums
// follow the recorded layers' in the same buffer ([layers + light layer][texel][rgb]).
class DeviceLightmap {
 public:
  DeviceLightmap(vulkan::Context& context, size_t texels, int layers, bool directional, int light_layers = 0);
  vulkan::TexelAccumulators sums;
  size_t texels = 0;
  int layers = 1;
  bool directional = false;
  int light_layers = 0;
  size_t bytes() const;
};

namespace vulkan {

// Device bytes of one estimate per texel (docs/runtime.md states them).
constexpr size_t device_lightmap_bytes_per_texel(int layers, bool directional) {
  return (directional ? 15 : 6) * 8 + size_t(layers) * 24 + 4;
}

// publish.comp's pipeline, its descriptor set and a counter buffer.
class LightmapPublisher {
 public:
  explicit LightmapPublisher(Context& context);
  LightmapPublisher(const LightmapPublisher&) = delete;
  LightmapPublisher& operator=(const LightmapPublisher&) = delete;

  // out := the rule of `mode` over the accumulation, `previous` and `base` (null where the mode
  // reads none; same shape as `out`). Waits for the device; returns the counts of published texels
  // with one sample and with two or more (read from host-visible memory: one submission in all).
  // `clear_accumulation`: the accumulation's sums are cleared after the dispatch, in the same
  // submission (an edit publishes what was shown, then starts again: LightmapDriver::start's
  // clear is then not needed).
  // `light_layers`: the light layers are composed too; false leaves out's as they were (what is
  // published then has no split by light to keep, and a publish copies every layer of every texel).
  PublishedLightmap publish(PublishMode mode, const TexelAccumulators& accumulation, const DeviceLightmap* previous,
                            const DeviceLightmap* base, std::shared_ptr<DeviceLightmap> out, bool clear_accumulation = false,
                            bool light_layers = true);
  // Writes `estimate`'s sums, layers and sample counts into `to` (same texels and layers).
  void upload(const LightmapEstimate& estimate, DeviceLightmap& to);

 private:
  void warm();
  void write_set(const std::array<VkDescriptorBufferInfo, 13>& infos);
  Context& context_;
  ComputeKernel kernel_;
  Buffer counts_;
};

}  // namespace vulkan
}  // namespace exitance
