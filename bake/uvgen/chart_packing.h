// Charts into one rectangle: each turned to its minimal-area bounding box, then skyline-packed in
// texel units with a gutter, at the largest density (up to the one asked) whose rectangle fits.
#pragma once
#include <vector>

#include "chart_parameterization.h"

namespace exitance::uvgen {

// A chart's points in 3-D-area units (UV area = 3-D area), before packing.
struct ChartOutline {
  std::vector<Point2> points;
};

struct PackingSettings {
  double texels_per_unit = 32;
  int max_side_texels = 2044;
  double gutter_texels = 3;
};

// Where every chart went: uv = (origin + rotate(point) * texels_per_unit) / side.
struct ChartPlacement {
  double cos_angle = 1, sin_angle = 0;  // rotation to the minimal-area bounding box, applied first
  Point2 min_after_rotation{};          // subtracted after the rotation (3-D-area units)
  Point2 extent{};                      // the rotated chart's width and height (3-D-area units)
  bool quarter_turn = false;            // then turned by 90 degrees to fit the skyline
  Point2 origin{};                      // texel position of the chart's box corner, gutter included
};

struct PackedCharts {
  std::vector<ChartPlacement> placements;
  int width = 0, height = 0;  // texels
  double texels_per_unit = 0;
  bool fits = true;           // false: the smallest density tried still exceeded max_side_texels

  // The chart point in normalized UVs (the rectangle divided by its longer side).
  Point2 uv(size_t chart, Point2 point) const;
};

PackedCharts pack_charts(const std::vector<ChartOutline>& charts, const PackingSettings& settings);

}  // namespace exitance::uvgen
