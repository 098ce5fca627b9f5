// Charts into one rectangle: each turned to its minimal-area bounding box and rasterized into a texel
// mask, then placed by bottom-left fill on the rectangle's texel occupancy (each chart, in one of its
// quarter turns, at the lowest then leftmost position where its mask overlaps no texel of the charts
// already placed dilated by the gutter), at the largest density, up to the one asked, whose
// rectangle fits the page. Masks let a chart nest inside another's arch or C, which bounding boxes
// and skylines cannot. The search tests 64 columns at a time against per-row run tables of the
// occupancy (two shifted reads per mask run), packs the strip widths on all hardware threads and
// gives up a strip as soon as its rectangle loses to another's; the placements are those of testing
// every position (bench/results/uvgen.md).
#pragma once
#include <functional>
#include <vector>

#include "chart_parameterization.h"

namespace exitance::uvgen {

// A chart's triangles (consecutive corner triples) in 3-D-area units (UV area = 3-D area). A point
// chart is one triangle with three equal corners.
struct ChartOutline {
  std::vector<Point2> points;
};

struct PackingSettings {
  double texels_per_unit = 32;
  int max_side_texels = 2044;
  // Least distance between two charts, in texels: masks are dilated by ceil(gutter) - 1 texels and
  // triangles rasterized grown by the rest over 2, so charts end at least `gutter_texels` apart.
  double gutter_texels = 3.1;
  // > 0: the caller keeps the packing only if it fits with texels_per_unit^2 / (width * height)
  // above this (a layout search); one that fits at texels_per_unit and fills no more comes back as
  // `beaten`, given up as soon as that is certain.
  double fill_to_beat = 0;
  std::function<void(double)> progress;  // fraction of the packing done, called from the calling thread
};

// Where every chart went: rotate to the minimal-area box, subtract its minimum, scale to texels,
// turn by quarter turns within its mask, then offset to the mask's texel position.
struct ChartPlacement {
  double cos_angle = 1, sin_angle = 0;  // rotation to the minimal-area bounding box, applied first
  Point2 min_after_rotation{};          // subtracted after the rotation (3-D-area units)
  Point2 extent{};                      // the rotated chart's width and height (3-D-area units)
  int quarter_turns = 0;                // 0..3, counter-clockwise, inside the mask
  int mask_width = 0, mask_height = 0;  // texels, before the turns
  Point2 origin{};                      // texel position of the turned mask's corner
};

struct PackedCharts {
  std::vector<ChartPlacement> placements;
  int width = 0, height = 0;  // texels
  double texels_per_unit = 0;
  bool fits = true;           // false: the smallest density tried still exceeded max_side_texels
  bool beaten = false;        // PackingSettings::fill_to_beat was not beaten: no placements

  // The chart point in normalized UVs (the rectangle divided by its longer side).
  Point2 uv(size_t chart, Point2 point) const;
};

// The chart's area over the area of its minimal-area bounding box (1 for a rectangle, low for an
// arch).
double bounding_box_fill(const ChartOutline& chart);

PackedCharts pack_charts(const std::vector<ChartOutline>& charts, const PackingSettings& settings);

}  // namespace exitance::uvgen
