// The texture-space filter of the indirect light (bundle/indirect_denoise.h) on the device, for what
// the runtime publishes: shaders/wavefront/denoise_indirect.comp reads a published device estimate
// and writes a filtered one, with the host filter's weights (exitance/common/texture_space_filter.h)
// and arithmetic, so page images and read-backs show the filtered light without a host pass. What
// the kernel reads of the G-buffer (per texel its position, normal, texel size and atlas place; per
// page pixel its texel) is uploaded once and patched where an edit moves texels.
#pragma once
#include <cstdint>
#include <vector>

#include "compute_kernel.h"
#include "device_lightmaps.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "vulkan_context.h"

namespace exitance::vulkan {

class IndirectDenoiser {
 public:
  IndirectDenoiser(Context& context, const TexelGBuffer& gbuffer);
  IndirectDenoiser(const IndirectDenoiser&) = delete;
  IndirectDenoiser& operator=(const IndirectDenoiser&) = delete;

  // Whether the uploaded records are those of `gbuffer`'s pages and texel count.
  bool fits(const TexelGBuffer& gbuffer) const;
  // The records of `texels` (G-buffer indices) taken from `gbuffer` again: texels an edit moved.
  void update_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& texels);
  // out := `in` with each sampled texel's indirect light filtered over a window of `radius` (1 to
  // 16) atlas texels, as denoise_indirect does it: totals synthesized from the filtered mean and
  // variance, layer 0 (the direct light) kept, layers 1 and up filtered with the same weights,
  // sample counts kept. `out` has `in`'s texels and recorded layers and neither L1 sums nor light
  // layers (they are not split into direct and indirect light); `in`'s are not read. One
  // submission, waited for (bounded). std::invalid_argument for another shape; the radius is
  // VulkanIntegrator::denoise_indirect's to check.
  // `totals_only`: only the sums and sample counts written (what page images read; out's layers are
  // left as they were), at about half the cost with the default four recorded layers.
  DeviceDenoiseCounts filter(const DeviceLightmap& in, DeviceLightmap& out, int radius, bool totals_only = false);

 private:
  Context& context_;
  size_t texels_ = 0;
  std::vector<uint32_t> page_sizes_;  // [width, height] per page
  Buffer records_buffer_, where_, pages_, pixels_, indirect_, counts_;
  ComputeKernel kernel_;
};

}  // namespace exitance::vulkan
