#include "exitance/runtime/refresh/baked_lightmap.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "exitance/formats/lightmap_exr.h"

namespace exitance {

namespace fs = std::filesystem;

std::optional<LightmapEstimate> read_baked_lightmap(const std::string& bundle, const formats::BundleManifest& manifest,
                                                    const TexelGBuffer& gbuffer, int recorded_bounces) {
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
  const char* needed[] = {"R", "G", "B", "direct.R", "direct.G", "direct.B", "error.Y"};
  for (size_t p = 0; p < manifest.pages.size(); ++p) {
    const std::string path = (fs::path(bundle) / manifest.pages[p].file).string();
    pages.push_back(formats::read_lightmap_exr(path));
    const formats::LightmapImage& image = pages.back();
    if (image.width != gbuffer.pages[p].width || image.height != gbuffer.pages[p].height)
      throw std::runtime_error(path + ": " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                               " pixels, but scene.bin's atlas page " + std::to_string(p) + " has " +
                               std::to_string(gbuffer.pages[p].width) + "x" + std::to_string(gbuffer.pages[p].height));
    for (const char* name : needed)
      if (!image.channels.count(name)) return std::nullopt;
  }

  LightmapEstimate estimate;
  const size_t n = gbuffer.texels.size();
  estimate.recorded_bounces = recorded_bounces;
  estimate.texels.resize(n);
  estimate.bounces.assign(size_t(recorded_bounces) * n * 3, 0.0);
  const double m = std::floor(minimum);
  for (size_t i = 0; i < n; ++i) {
    const LiveTexel& texel = gbuffer.texels[i];
    const formats::LightmapImage& page = pages[texel.page];
    const size_t at = size_t(texel.y) * size_t(page.width) + size_t(texel.x);
    // Sealed texels the bake skipped hold dilated neighbours, not estimates: nothing to start from.
    const auto valid = page.channels.find("valid");
    if (valid != page.channels.end() && !(valid->second[at] > 0)) continue;
    const Vec3 total{page.channels.at("R")[at], page.channels.at("G")[at], page.channels.at("B")[at]};
    const Vec3 direct{page.channels.at("direct.R")[at], page.channels.at("direct.G")[at], page.channels.at("direct.B")[at]};
    const double relative = page.channels.at("error.Y")[at];
    bool finite = std::isfinite(relative) && relative >= 0;
    for (int c = 0; c < 3; ++c) finite = finite && std::isfinite(total[c]) && std::isfinite(direct[c]);
    if (!finite) continue;
    const double y = std::max(0.0f, luminance(total));
    const double se = relative * (y + floor);
    TexelAccumulator& t = estimate.texels[i];
    t.samples = uint32_t(m);
    for (int c = 0; c < 3; ++c) {
      // The luminance's relative error for every channel (error.Y is all the bundle keeps).
      const double variance = y > 0 ? se * se * (double(total[c]) / y) * (double(total[c]) / y) : se * se;
      t.total[c] = m * total[c];
      t.total_squared[c] = m * double(total[c]) * total[c] + m * (m - 1) * variance;
      t.direct[c] = m * direct[c];
      estimate.bounces[i * 3 + size_t(c)] = m * direct[c];
      if (recorded_bounces > 1) estimate.bounces[(n + i) * 3 + size_t(c)] = m * (double(total[c]) - direct[c]);
    }
  }
  return estimate;
}

}  // namespace exitance
