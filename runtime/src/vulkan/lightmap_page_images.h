// The published lightmap written into device images, one RGBA32F image per atlas page (E/pi in RGB,
// coverage in A), gutters dilated as bundle/lightmap_assembly.cpp dilates them: the same
// neighbours, sums and rounding, so an image equals what read_page returns, without a read-back.
// shaders/wavefront/page_images.comp does the work; the host works out once which pixel takes which
// texel and in which dilation ring it is filled.
#pragma once
#include <cstdint>
#include <vector>

#include "compute_kernel.h"
#include "device_lightmaps.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/vulkan/device_page_images.h"
#include "vulkan_context.h"

namespace exitance::vulkan {

// Per pixel: the live texel it shows (kNoTexel: none) and the ring that fills it (0: a chart
// pixel; k: dilation pass k; kNeverFilled: beyond the dilation), as dilate_into_gutter decides.
struct PagePixelRings {
  static constexpr uint32_t kNoTexel = 0xffffffffu, kNeverFilled = 0xffffffffu;
  std::vector<uint32_t> texel, ring;
  uint32_t rings = 0;  // the deepest ring used
};
PagePixelRings page_pixel_rings(const TexelGBuffer& gbuffer, size_t page, int dilation_texels);

class LightmapPageImages {
 public:
  // Images (and their semaphore) for `gbuffer`'s pages; `dilation_texels` as AssemblyOptions.
  LightmapPageImages(Context& context, const TexelGBuffer& gbuffer, int dilation_texels);
  ~LightmapPageImages();
  LightmapPageImages(const LightmapPageImages&) = delete;
  LightmapPageImages& operator=(const LightmapPageImages&) = delete;

  // Whether these images are those of `gbuffer`'s pages and texels with this dilation.
  bool fits(const TexelGBuffer& gbuffer, int dilation_texels) const;
  // Writes `lightmap` (a published estimate of the G-buffer's texels) into the images in one
  // submission, after every command submitted to the queue before it, signals the semaphore and
  // waits for it (bounded).
  const DevicePageImages& write(const DeviceLightmap& lightmap);
  const DevicePageImages& images() const { return images_; }
  // Page `page`'s pixels read back, RGBA row by row (row 0 at the top): for tests and tools.
  std::vector<float> read_back(size_t page);

 private:
  void release();
  Context& context_;
  size_t texels_ = 0;
  int dilation_ = 0;
  std::vector<uint32_t> first_pixel_, rings_;  // per page
  Buffer pixels_;                              // [pixel][texel, ring, coverage bits], pages in turn
  std::vector<VkDeviceMemory> memory_;
  DevicePageImages images_;
  bool initialized_ = false;  // the images left UNDEFINED for GENERAL
  ComputeKernel kernel_;
};

}  // namespace exitance::vulkan
