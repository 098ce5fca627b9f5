#include "exitance/bake/command/expand_lightmap_estimate.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace exitance {
namespace {

// Scatters a per-texel field laid out as [layer][texel][element] (a plain per-texel vector is one
// layer of one element) from the traced texels to all texels; skipped texels get T{}. The element
// count is inferred from the size, so the same call serves per-texel scalars and RGB triples.
template <class T>
std::vector<T> scatter_per_texel(const std::vector<T>& traced, const std::vector<size_t>& full_index, size_t full_count,
                                 size_t layers, const char* field) {
  if (traced.empty()) return {};
  const size_t n = full_index.size();
  if (n == 0 || layers == 0 || traced.size() % (n * layers) != 0)
    throw std::logic_error(std::string("expand_lightmap_estimate: ") + field + " has " + std::to_string(traced.size()) +
                           " entries, not a multiple of " + std::to_string(layers) + " layers x " + std::to_string(n) +
                           " traced texels");
  const size_t elements = traced.size() / (n * layers);
  std::vector<T> full(layers * full_count * elements, T{});
  for (size_t layer = 0; layer < layers; ++layer)
    for (size_t k = 0; k < n; ++k)
      for (size_t e = 0; e < elements; ++e)
        full[(layer * full_count + full_index[k]) * elements + e] = traced[(layer * n + k) * elements + e];
  return full;
}

}  // namespace

// A new per-texel field of LightmapEstimate (estimates.h) must be added below: the copy at the top
// carries every other field over unchanged, which for a per-texel vector would leave it indexed by
// traced texel. The static_assert is there to make a new field fail the build here until it is.
static_assert(sizeof(LightmapEstimate) == 496,  // guiding_*, emitter_guiding, light_subpath*, pilot_samples_dropped: not per texel
              "LightmapEstimate changed: scatter its new per-texel fields in expand_lightmap_estimate, then update "
              "this size");

LightmapEstimate expand_lightmap_estimate(LightmapEstimate traced, const std::vector<uint8_t>& skipped) {
  std::vector<size_t> full_index;
  full_index.reserve(skipped.size());
  for (size_t i = 0; i < skipped.size(); ++i)
    if (!skipped[i]) full_index.push_back(i);
  if (full_index.size() != traced.texels.size())
    throw std::logic_error("expand_lightmap_estimate: " + std::to_string(traced.texels.size()) +
                           " traced texels for " + std::to_string(full_index.size()) + " unskipped ones");
  const size_t all = skipped.size();
  std::vector<TexelAccumulator> texels = scatter_per_texel(traced.texels, full_index, all, 1, "texels");
  std::vector<double> bounces =
      scatter_per_texel(traced.bounces, full_index, all, size_t(traced.recorded_bounces), "bounces");
  std::vector<double> sh1 = scatter_per_texel(traced.sh1, full_index, all, 1, "sh1");  // [texel][axis][rgb]: 9 elements
  std::vector<double> light_sums =
      scatter_per_texel(traced.light_sums, full_index, all, size_t(traced.light_layers), "light_sums");
  LightmapEstimate full = std::move(traced);  // the fields that are not per texel
  full.texels = std::move(texels);
  full.bounces = std::move(bounces);
  full.sh1 = std::move(sh1);
  full.light_sums = std::move(light_sums);
  return full;
}

}  // namespace exitance
