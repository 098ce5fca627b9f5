// The last layer pass of a time budget in the per-bounce mode (core/per_bounce_bake.h): the whole
// samples that fit, then one more sample for a part of the texels, so the budget is spent to within
// a small part of one sample of every texel instead of leaving out the pass that does not fit.
// Each texel's estimate stays the mean of its own samples (counts differ by at most one), so it
// stays unbiased.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace exitance {

// What of a layer pass of `wanted` samples per texel fits in `seconds_left`, at `seconds_per_sample`
// (one sample of every texel): `whole` samples, and when those are fewer than wanted, one more
// sample for `fraction` of the texels (0, or in [kSmallestPartialFraction, 1)).
struct LayerPassCut {
  uint32_t whole = 0;
  double fraction = 0;
  bool cut = false;  // fewer than wanted: the budget ends with this pass
};

// A partial pass over fewer texels than this is not worth its fixed costs (its allocations, the
// exchange between processes): the time is left unspent (at most this part of one sample's time).
constexpr double kSmallestPartialFraction = 1e-3;

// seconds_per_sample <= 0 (not yet measured): every wanted sample, uncut.
LayerPassCut cut_layer_pass(double seconds_left, double seconds_per_sample, uint32_t wanted);

// Which texels a partial pass covering `fraction` of them samples: a hash of the texel's index
// (splitmix64 of `salt` + index below fraction * 2^53), so the chosen texels are spread over the
// whole atlas, the pass costs about its fraction of a full one, and every process picks the same
// texels by their global indices.
class PartialPassTexels {
 public:
  // `salt`: the seed, layer and sample (a different choice per layer and sample).
  PartialPassTexels(double fraction, uint64_t seed, int layer, uint32_t sample);
  bool covers(size_t texel) const;
  // The covered texels of [begin, end), ascending.
  std::vector<uint32_t> in_range(size_t begin, size_t end) const;

 private:
  uint64_t covered_below_;
  uint64_t salt_;
};

}  // namespace exitance
