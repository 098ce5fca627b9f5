#include "exitance/runtime/bundle/lightmap_assembly.h"

#include <cstdint>
#include <string>
#include <utility>

namespace exitance {

void dilate_into_gutter(int width, int height, const std::vector<float>& coverage, std::vector<float*> channels,
                        int passes) {
  std::vector<uint8_t> filled(coverage.size());
  for (size_t i = 0; i < coverage.size(); ++i) filled[i] = coverage[i] > 0 ? 1 : 0;
  dilate_into(width, height, std::move(filled), std::vector<uint8_t>(coverage.size(), 1), std::move(channels), passes);
}

void dilate_into(int width, int height, std::vector<uint8_t> filled, const std::vector<uint8_t>& fillable,
                 std::vector<float*> channels, int passes) {
  std::vector<size_t> newly;
  std::vector<float> values;
  for (int pass = 0; passes < 0 || pass < passes; ++pass) {
    newly.clear();
    values.clear();
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const size_t i = size_t(y) * size_t(width) + size_t(x);
        if (filled[i] || !fillable[i]) continue;
        std::vector<double> sum(channels.size(), 0.0);
        int n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            const size_t j = size_t(ny) * size_t(width) + size_t(nx);
            if (!filled[j]) continue;
            for (size_t c = 0; c < channels.size(); ++c) sum[c] += channels[c][j];
            ++n;
          }
        if (n == 0) continue;
        newly.push_back(i);
        for (double s : sum) values.push_back(float(s / n));
      }
    if (newly.empty()) break;
    for (size_t k = 0; k < newly.size(); ++k) {
      filled[newly[k]] = 1;
      for (size_t c = 0; c < channels.size(); ++c) channels[c][newly[k]] = values[k * channels.size() + c];
    }
  }
}

std::vector<formats::LightmapImage> assemble_lightmap_pages(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate,
                                                            const AssemblyOptions& options,
                                                            const std::vector<uint8_t>& untraced) {
  std::vector<std::string> layers = {"", "direct.", "indirect."};
  if (options.bounce_layers)
    for (int k = 0; k < estimate.recorded_bounces; ++k) layers.push_back("bounce" + std::to_string(k) + ".");
  if (estimate.has_sh1())
    for (const char* axis : {"x", "y", "z"}) layers.push_back(std::string("sh1.") + axis + ".");
  std::vector<formats::LightmapImage> pages(gbuffer.pages.size());
  for (size_t p = 0; p < pages.size(); ++p) {
    const AtlasPage& source = gbuffer.pages[p];
    pages[p].width = source.width;
    pages[p].height = source.height;
    const size_t n = size_t(source.width) * size_t(source.height);
    for (const std::string& layer : layers)
      for (const char* c : {"R", "G", "B"}) pages[p].channels[layer + c].assign(n, 0.0f);
    pages[p].channels["A"] = source.coverage;
    pages[p].channels["error.Y"].assign(n, 0.0f);
    pages[p].channels["valid"].assign(n, 0.0f);
  }
  const double error_floor = estimate.error_floor();
  // Per page, the texels to fill from traced neighbours before the gutter is dilated.
  std::vector<std::vector<uint8_t>> skipped(pages.size());
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& texel = gbuffer.texels[i];
    formats::LightmapImage& page = pages[texel.page];
    const size_t at = size_t(texel.y) * size_t(page.width) + size_t(texel.x);
    if (!untraced.empty() && untraced[i]) {
      if (skipped[texel.page].empty()) skipped[texel.page].assign(page.channels["valid"].size(), 0);
      skipped[texel.page][at] = 1;
      continue;
    }
    page.channels["valid"][at] = 1.0f;
    const Vec3 total = estimate.mean_total(i), direct = estimate.mean_direct(i);
    const Vec3 indirect = total - direct;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      page.channels[names[c]][at] = total[c];
      page.channels[std::string("direct.") + names[c]][at] = direct[c];
      page.channels[std::string("indirect.") + names[c]][at] = std::max(0.0f, indirect[c]);
    }
    page.channels["error.Y"][at] = estimate.relative_standard_error(i, error_floor);
    if (options.bounce_layers)
      for (int k = 0; k < estimate.recorded_bounces; ++k) {
        const Vec3 b = estimate.mean_bounce(k, i);
        for (int c = 0; c < 3; ++c) page.channels["bounce" + std::to_string(k) + "." + names[c]][at] = b[c];
      }
    if (estimate.has_sh1())
      for (int axis = 0; axis < 3; ++axis) {
        const Vec3 l1 = estimate.mean_sh1(axis, i);
        for (int c = 0; c < 3; ++c) page.channels[std::string("sh1.") + "xyz"[axis] + "." + names[c]][at] = l1[c];
      }
  }
  for (size_t p = 0; p < pages.size(); ++p) {
    std::vector<float*> channels;
    for (auto& [name, data] : pages[p].channels)
      if (name != "A" && name != "valid") channels.push_back(data.data());
    if (!skipped[p].empty()) {
      // Untraced texels from the traced ones only, as deep as the untraced region is, and only
      // across chart texels (never from another chart through the gutter).
      const std::vector<float>& valid = pages[p].channels["valid"];
      std::vector<uint8_t> traced(valid.size());
      for (size_t i = 0; i < valid.size(); ++i) traced[i] = valid[i] > 0 ? 1 : 0;
      dilate_into(pages[p].width, pages[p].height, std::move(traced), skipped[p], channels, -1);
    }
    dilate_into_gutter(pages[p].width, pages[p].height, gbuffer.pages[p].coverage, channels, options.dilation_texels);
  }
  return pages;
}

}  // namespace exitance
