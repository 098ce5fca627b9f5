#include "exitance/runtime/bundle/light_layer_pages.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string_view>

#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance {

namespace {
constexpr const char* kChannelNames[3] = {"R", "G", "B"};
}

std::string light_layer_channel(uint32_t layer, int channel) {
  return "layer" + std::to_string(layer) + "." + kChannelNames[channel];
}

std::optional<LightLayerChannel> parse_light_layer_channel(const std::string& name) {
  constexpr std::string_view prefix = "layer";
  if (name.size() < prefix.size() + 3 || name.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  const size_t dot = name.size() - 2;
  if (name[dot] != '.') return std::nullopt;
  LightLayerChannel parsed;
  const char c = name[dot + 1];
  if (c == 'R') parsed.channel = 0;
  else if (c == 'G') parsed.channel = 1;
  else if (c == 'B') parsed.channel = 2;
  else return std::nullopt;
  const std::string digits = name.substr(prefix.size(), dot - prefix.size());
  if (digits.empty() || digits.size() > 6 || (digits.size() > 1 && digits[0] == '0')) return std::nullopt;
  for (char d : digits)
    if (d < '0' || d > '9') return std::nullopt;
  parsed.layer = uint32_t(std::stoul(digits));
  return parsed;
}

std::vector<formats::LightmapImage> assemble_light_layer_pages(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate,
                                                               const std::vector<uint32_t>& bundle_layer) {
  const size_t n = gbuffer.texels.size();
  if (bundle_layer.size() != size_t(estimate.light_layers) || estimate.light_sums.size() != size_t(estimate.light_layers) * n * 3 ||
      estimate.texels.size() != n)
    throw std::invalid_argument("assemble_light_layer_pages: the estimate's light layers do not match the G-buffer and the layer map");
  uint32_t bundle_layers = 0;
  for (uint32_t b : bundle_layer) bundle_layers = std::max(bundle_layers, b + 1);
  // Which bundle layers light some texel of each page: only those get channels.
  std::vector<std::vector<uint8_t>> used(gbuffer.pages.size(), std::vector<uint8_t>(bundle_layers, 0));
  for (size_t j = 0; j < bundle_layer.size(); ++j)
    for (size_t i = 0; i < n; ++i) {
      const double* s = &estimate.light_sums[(j * n + i) * 3];
      if (s[0] != 0 || s[1] != 0 || s[2] != 0) used[gbuffer.texels[i].page][bundle_layer[j]] = 1;
    }
  std::vector<formats::LightmapImage> pages(gbuffer.pages.size());
  std::vector<std::vector<std::array<float*, 3>>> targets(pages.size(), std::vector<std::array<float*, 3>>(bundle_layers));
  for (size_t p = 0; p < pages.size(); ++p) {
    pages[p].width = gbuffer.pages[p].width;
    pages[p].height = gbuffer.pages[p].height;
    const size_t pixels = size_t(pages[p].width) * size_t(pages[p].height);
    for (uint32_t b = 0; b < bundle_layers; ++b) {
      if (!used[p][b]) continue;
      for (int c = 0; c < 3; ++c) pages[p].channels[light_layer_channel(b, c)].assign(pixels, 0.0f);
    }
    for (uint32_t b = 0; b < bundle_layers; ++b)
      if (used[p][b])
        for (int c = 0; c < 3; ++c) targets[p][b][c] = pages[p].channels[light_layer_channel(b, c)].data();
  }
  // Every live texel writes its own cells: the texels run in parallel.
  for_each_chunk(n, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const LiveTexel& texel = gbuffer.texels[i];
      const uint32_t samples = estimate.texels[i].samples;
      if (samples == 0) continue;
      const size_t at = size_t(texel.y) * size_t(pages[texel.page].width) + size_t(texel.x);
      for (size_t j = 0; j < bundle_layer.size(); ++j) {
        const std::array<float*, 3>& out = targets[texel.page][bundle_layer[j]];
        if (!out[0]) continue;  // zero on this whole page
        for (int c = 0; c < 3; ++c) out[c][at] += float(estimate.light_sums[(j * n + i) * 3 + size_t(c)] / samples);
      }
    }
  });
  return pages;
}

std::vector<float> read_light_layer_pages(const std::vector<std::string>& files, const TexelGBuffer& gbuffer,
                                          uint32_t layer_count) {
  if (files.size() != gbuffer.pages.size())
    throw std::runtime_error("light layers: " + std::to_string(files.size()) + " files for " + std::to_string(gbuffer.pages.size()) +
                             " atlas pages");
  const size_t n = gbuffer.texels.size();
  std::vector<float> means(size_t(layer_count) * n * 3, 0.0f);
  // Per page, per layer and channel, the pixels (null: the layer is 0 on that page).
  std::vector<formats::LightmapImage> pages;
  std::vector<std::vector<std::array<const float*, 3>>> layers(files.size());
  for (size_t p = 0; p < files.size(); ++p) {
    pages.push_back(read_atlas_page(files[p], gbuffer, p));
    const formats::LightmapImage& image = pages.back();
    layers[p].assign(layer_count, {nullptr, nullptr, nullptr});
    for (const auto& [name, pixels] : image.channels) {
      const std::optional<LightLayerChannel> parsed = parse_light_layer_channel(name);
      if (!parsed) throw std::runtime_error(files[p] + ": channel \"" + name + "\" is not a light layer (layer<k>.R/G/B)");
      if (parsed->layer >= layer_count)
        throw std::runtime_error(files[p] + ": channel \"" + name + "\": layer " + std::to_string(parsed->layer) +
                                 " is not below the manifest's light_layers.count " + std::to_string(layer_count));
      layers[p][parsed->layer][size_t(parsed->channel)] = pixels.data();
    }
    for (uint32_t k = 0; k < layer_count; ++k) {
      const auto& l = layers[p][k];
      const int present = (l[0] != nullptr) + (l[1] != nullptr) + (l[2] != nullptr);
      if (present != 0 && present != 3)
        throw std::runtime_error(files[p] + ": layer " + std::to_string(k) + " has " + std::to_string(present) +
                                 " of its R, G, B channels");
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const LiveTexel& texel = gbuffer.texels[i];
    const size_t at = size_t(texel.y) * size_t(gbuffer.pages[texel.page].width) + size_t(texel.x);
    for (uint32_t k = 0; k < layer_count; ++k) {
      const std::array<const float*, 3>& l = layers[texel.page][k];
      if (!l[0]) continue;
      for (int c = 0; c < 3; ++c) {
        const float v = l[size_t(c)][at];
        if (!std::isfinite(v))
          throw std::runtime_error(files[texel.page] + ": channel \"" + light_layer_channel(k, c) + "\" at pixel (" +
                                   std::to_string(texel.x) + ", " + std::to_string(texel.y) + "): not finite");
        means[(size_t(k) * n + i) * 3 + size_t(c)] = v;
      }
    }
  }
  return means;
}

}  // namespace exitance
