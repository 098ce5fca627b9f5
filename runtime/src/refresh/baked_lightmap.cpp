#include "exitance/runtime/refresh/baked_lightmap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/bundle/light_layer_pages.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/refresh/published_estimate.h"

namespace exitance {

namespace fs = std::filesystem;

std::optional<LightmapEstimate> read_baked_lightmap(const std::string& bundle, const formats::BundleManifest& manifest,
                                                    const TexelGBuffer& gbuffer, int recorded_bounces,
                                                    BakedLightLayers light_layers, bool* has_light_layers) {
  if (has_light_layers) *has_light_layers = false;
  // A relit bundle's pages are described by its "relight" report, a baked one's by "stats".
  const std::string& described = manifest.relight_json.empty() ? manifest.stats_json : manifest.relight_json;
  if (manifest.pages.empty() || manifest.pages.size() != gbuffer.pages.size() || described.empty()) return std::nullopt;
  const formats::BakeSettings settings = manifest.settings.value_or(formats::BakeSettings{});
  if (settings.directional != "off") return std::nullopt;
  const nlohmann::json stats = nlohmann::json::parse(described, nullptr, false);
  if (stats.is_discarded() || !stats.is_object()) return std::nullopt;
  const nlohmann::json* samples = stats.contains("samples_per_texel") ? &stats["samples_per_texel"] : nullptr;
  if (!samples || !samples->is_object() || !samples->contains("min") || !(*samples)["min"].is_number()) return std::nullopt;
  const double minimum = (*samples)["min"].get<double>();
  if (!(minimum >= kBakedStartMinimumSamples) || minimum > 4e9) return std::nullopt;
  double floor = -1;
  if (stats.contains("error") && stats["error"].is_object() && stats["error"].contains("floor") && stats["error"]["floor"].is_number())
    floor = stats["error"]["floor"].get<double>();
  if (!(floor >= 0)) return std::nullopt;

  std::vector<formats::LightmapImage> pages;
  // Per page, the channels read per texel: R, G, B, direct.R, direct.G, direct.B, error.Y, and valid
  // (null when the page has none).
  const char* needed[] = {"R", "G", "B", "direct.R", "direct.G", "direct.B", "error.Y"};
  std::vector<std::array<const float*, 8>> channels;
  for (size_t p = 0; p < manifest.pages.size(); ++p) {
    const std::string path = (fs::path(bundle) / manifest.pages[p].file).string();
    pages.push_back(read_atlas_page(path, gbuffer, p));
    const formats::LightmapImage& image = pages.back();
    std::array<const float*, 8>& page = channels.emplace_back();
    for (size_t k = 0; k < 7; ++k) {
      const auto found = image.channels.find(needed[k]);
      if (found == image.channels.end()) return std::nullopt;
      page[k] = found->second.data();
    }
    const auto valid = image.channels.find("valid");
    page[7] = valid == image.channels.end() ? nullptr : valid->second.data();
  }

  // The bundle's light layers, checked against the layout the session's scene has.
  std::vector<float> layer_means;
  const bool read_layers = light_layers.count > 0 && manifest.light_layers.has_value();
  if (read_layers) {
    const formats::LightLayersInfo& info = *manifest.light_layers;
    const std::string where = (fs::path(bundle) / "manifest.json").string() + ": light_layers";
    if (info.count != light_layers.count || info.punctual != light_layers.punctual)
      throw std::runtime_error(where + ": " + std::to_string(info.count) + " layers, " + std::to_string(info.punctual) +
                               " of them punctual lights', but scene.bin's lights and emissive materials make " +
                               std::to_string(light_layers.count) + ", " + std::to_string(light_layers.punctual) +
                               " punctual (docs/bundle.md \"Light layers\")");
    std::vector<std::string> files;
    for (const std::string& file : info.files) files.push_back((fs::path(bundle) / file).string());
    layer_means = read_light_layer_pages(files, gbuffer, info.count);
  }

  LightmapEstimate estimate;
  const size_t n = gbuffer.texels.size();
  estimate.light_layers = int(light_layers.count);
  estimate.light_sums.assign(size_t(light_layers.count) * n * 3, 0.0);
  estimate.recorded_bounces = recorded_bounces;
  estimate.texels.resize(n);
  estimate.bounces.assign(size_t(recorded_bounces) * n * 3, 0.0);
  const uint32_t m = uint32_t(minimum);
  for (size_t i = 0; i < n; ++i) {
    const LiveTexel& texel = gbuffer.texels[i];
    const std::array<const float*, 8>& page = channels[texel.page];
    const size_t at = size_t(texel.y) * size_t(pages[texel.page].width) + size_t(texel.x);
    // Sealed texels the bake skipped hold dilated neighbours, not estimates: nothing to start from.
    if (page[7] && !(page[7][at] > 0)) continue;
    const Vec3 total{page[0][at], page[1][at], page[2][at]};
    const Vec3 direct{page[3][at], page[4][at], page[5][at]};
    const double relative = page[6][at];
    bool finite = std::isfinite(relative) && relative >= 0;
    for (int c = 0; c < 3; ++c) finite = finite && std::isfinite(total[c]) && std::isfinite(direct[c]);
    if (!finite) continue;
    const double y = std::max(0.0f, luminance(total));
    const double se = relative * (y + floor);
    double mean[3], variance[3];
    for (int c = 0; c < 3; ++c) {
      // The luminance's relative error for every channel (error.Y is all the bundle keeps).
      mean[c] = total[c];
      variance[c] = y > 0 ? se * se * (double(total[c]) / y) * (double(total[c]) / y) : se * se;
    }
    TexelAccumulator& t = estimate.texels[i];
    set_total_sums(t, m, mean, variance);
    for (int c = 0; c < 3; ++c) {
      t.direct[c] = double(m) * direct[c];
      estimate.bounces[i * 3 + size_t(c)] = double(m) * direct[c];
      if (recorded_bounces > 1) estimate.bounces[(n + i) * 3 + size_t(c)] = double(m) * (double(total[c]) - direct[c]);
    }
    if (read_layers)
      for (size_t k = 0; k < light_layers.count; ++k)
        for (size_t c = 0; c < 3; ++c) estimate.light_sums[(k * n + i) * 3 + c] = double(m) * layer_means[(k * n + i) * 3 + c];
  }
  if (has_light_layers) *has_light_layers = read_layers;
  return estimate;
}

}  // namespace exitance
