#include "exitance/runtime/core/partial_layer_pass.h"

#include <algorithm>
#include <cmath>

#include "exitance/common/rng.h"

namespace exitance {

LayerPassCut cut_layer_pass(double seconds_left, double seconds_per_sample, uint32_t wanted) {
  LayerPassCut cut;
  cut.whole = wanted;
  if (!(seconds_per_sample > 0)) return cut;
  const double samples = std::max(0.0, seconds_left) / seconds_per_sample;
  if (!(samples < double(wanted))) return cut;
  cut.cut = true;
  cut.whole = uint32_t(std::floor(samples));
  cut.fraction = samples - double(cut.whole);
  if (cut.fraction < kSmallestPartialFraction) cut.fraction = 0;
  return cut;
}

PartialPassTexels::PartialPassTexels(double fraction, uint64_t seed, int layer, uint32_t sample)
    : covered_below_(uint64_t(std::clamp(fraction, 0.0, 1.0) * 0x1.0p53)),
      salt_(splitmix64(seed ^ (uint64_t(uint32_t(layer)) << 32) ^ sample ^ (0x9A87'1A1Bull << 20))) {}

bool PartialPassTexels::covers(size_t texel) const {
  return (splitmix64(salt_ + uint64_t(texel)) >> 11) < covered_below_;
}

std::vector<uint32_t> PartialPassTexels::in_range(size_t begin, size_t end) const {
  std::vector<uint32_t> texels;
  for (size_t i = begin; i < end; ++i)
    if (covers(i)) texels.push_back(uint32_t(i));
  return texels;
}

}  // namespace exitance
