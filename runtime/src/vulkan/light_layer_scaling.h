// An edit that only scaled lights' emission, applied to estimates kept on the device
// (shaders/wavefront/scale_light_layers.comp): the scaled light layers times their factors, the
// totals by the change, the rest in proportion; a texel whose layers do not split its total (the
// baked lightmap's) in proportion to the accumulation's split. Zero rays; one submission.
#pragma once
#include <vector>

#include "exitance/runtime/vec_math.h"
#include "compute_kernel.h"
#include "vulkan_context.h"
#include "wavefront_buffers.h"

namespace exitance::vulkan {

// One estimate's buffers and shape (the accumulation's or a DeviceLightmap's).
struct ScaledEstimate {
  const TexelAccumulators* sums = nullptr;
  size_t texels = 0;
  int recorded = 1;
  int light_layers = 0;
  bool directional = false;
  bool proportional = false;  // its light layers do not split its totals: scaled by the accumulation's split
};

class LightLayerScaler {
 public:
  explicit LightLayerScaler(Context& context);
  // `factors`: per light layer, rgb and w = 1 where the layer is scaled (w = 0: kept). Every
  // estimate must have factors.size() light layers; `others` (previous, ...) are scaled first
  // (exactly, or by the accumulation's split where they are `proportional`), then the accumulation.
  void scale(const std::vector<Vec4>& factors, const ScaledEstimate& accumulation, const std::vector<ScaledEstimate>& others);

 private:
  static constexpr uint32_t kSets = 4;  // the accumulation, previous, base, published
  Context& context_;
  ComputeKernel kernel_;
  Buffer factors_;
};

}  // namespace exitance::vulkan
