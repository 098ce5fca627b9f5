#include "lightmap_chart_packer.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace exitance::samples {
namespace {

constexpr float kBorder = kLightmapChartPadding / 2.0f;

// Shelf packing: charts sorted tallest first fill rows left to right. Simple,
// deterministic and good enough for the few dozen rectangles a sample mesh has.
// Returns false when the charts do not fit at this scale.
bool tryShelfPacking(const std::vector<ChartSize>& landscapeCharts, const std::vector<size_t>& order,
                     float scale, std::vector<PlacedChart>& placed) {
  float cursorX = kBorder, shelfY = kBorder, shelfHeight = 0.0f;
  for (size_t index : order) {
    const float w = landscapeCharts[index].width * scale;
    const float h = landscapeCharts[index].height * scale;
    if (cursorX + w > 1.0f - kBorder && cursorX > kBorder) {
      shelfY += shelfHeight + kLightmapChartPadding;
      cursorX = kBorder;
      shelfHeight = 0.0f;
    }
    if (cursorX + w > 1.0f - kBorder || shelfY + h > 1.0f - kBorder) return false;
    placed[index].x = cursorX;
    placed[index].y = shelfY;
    placed[index].width = w;
    placed[index].height = h;
    cursorX += w + kLightmapChartPadding;
    shelfHeight = std::max(shelfHeight, h);
  }
  return true;
}

}  // namespace

std::vector<PlacedChart> packLightmapCharts(const std::vector<ChartSize>& charts) {
  // Turn every chart to landscape: rows of wide charts waste less height.
  std::vector<ChartSize> landscape(charts);
  std::vector<PlacedChart> placed(charts.size());
  float largestSide = 0.0f;
  for (size_t i = 0; i < charts.size(); ++i) {
    if (charts[i].height > charts[i].width) {
      std::swap(landscape[i].width, landscape[i].height);
      placed[i].turned = true;
    }
    largestSide = std::max(largestSide, landscape[i].width);
  }
  if (charts.empty()) return placed;

  std::vector<size_t> order(charts.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (landscape[a].height != landscape[b].height) return landscape[a].height > landscape[b].height;
    return landscape[a].width > landscape[b].width;
  });

  // Largest scale that packs, found by bisection. Shelf packing is not strictly
  // monotonic in scale, so keep the best scale that was actually seen to fit.
  float low = 0.0f, high = (1.0f - kLightmapChartPadding) / largestSide;
  std::vector<PlacedChart> attempt = placed, best;
  for (int iteration = 0; iteration < 40; ++iteration) {
    const float scale = 0.5f * (low + high);
    if (tryShelfPacking(landscape, order, scale, attempt)) {
      low = scale;
      best = attempt;
    } else {
      high = scale;
    }
  }
  if (best.empty())
    throw std::runtime_error("lightmap layout: " + std::to_string(charts.size()) +
                             " charts do not fit in [0,1]² with the required padding");
  verifyChartsDisjoint(best);
  return best;
}

void verifyChartsDisjoint(const std::vector<PlacedChart>& charts) {
  // A hair of slack for float rounding; gaps are 1/32 so this cannot hide an overlap.
  constexpr float kSlack = 1e-6f;
  for (size_t i = 0; i < charts.size(); ++i) {
    const PlacedChart& a = charts[i];
    if (a.x < kBorder - kSlack || a.y < kBorder - kSlack || a.x + a.width > 1.0f - kBorder + kSlack ||
        a.y + a.height > 1.0f - kBorder + kSlack || a.width <= 0.0f || a.height <= 0.0f)
      throw std::logic_error("lightmap layout: chart " + std::to_string(i) + " leaves the unit square");
    for (size_t j = i + 1; j < charts.size(); ++j) {
      const PlacedChart& b = charts[j];
      const bool apartInX = a.x + a.width + kLightmapChartPadding <= b.x + kSlack ||
                            b.x + b.width + kLightmapChartPadding <= a.x + kSlack;
      const bool apartInY = a.y + a.height + kLightmapChartPadding <= b.y + kSlack ||
                            b.y + b.height + kLightmapChartPadding <= a.y + kSlack;
      if (!apartInX && !apartInY)
        throw std::logic_error("lightmap layout: charts " + std::to_string(i) + " and " + std::to_string(j) +
                               " are closer than the padding");
    }
  }
}

}  // namespace exitance::samples
