// Packs one mesh's lightmap charts (rectangles in metres) into the unit square
// for TEXCOORD_1: one uniform scale for all charts so texel density is the same
// over the mesh, aspect ratios kept, and a gutter between charts so bilinear
// lookups and dilation never mix two charts.
#pragma once

#include <vector>

namespace exitance::samples {

// Gap between two charts in UV units: 2 texels of a 64-texel-wide mesh region.
// Charts keep half of it to the square's border, so meshes placed side by side
// in an atlas page are separated by the full gap too.
inline constexpr float kLightmapChartPadding = 2.0f / 64.0f;

struct ChartSize {
  float width = 0.0f;   // metres along the chart's first edge
  float height = 0.0f;  // metres along its second edge
};

struct PlacedChart {
  float x = 0.0f, y = 0.0f;           // lower corner in [0,1]²
  float width = 0.0f, height = 0.0f;  // extent in UV units after scaling (and turning)
  bool turned = false;                // true: the chart's first edge runs along V
};

// Returns one placement per input chart, in input order. Throws std::runtime_error
// when the charts cannot fit even at a vanishing scale (too many charts for the gutter).
std::vector<PlacedChart> packLightmapCharts(const std::vector<ChartSize>& charts);

// Throws std::logic_error unless every chart lies inside [0,1]² with half the
// padding to the border and every pair is at least the padding apart.
void verifyChartsDisjoint(const std::vector<PlacedChart>& charts);

}  // namespace exitance::samples
