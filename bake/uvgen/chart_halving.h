// A chart cut in two across the long axis of its flattening: an arch (a torus's chart) becomes two
// shorter arches that fill more of their bounding boxes and stack into one another.
#pragma once
#include <vector>

#include "chart_parameterization.h"

namespace exitance::uvgen {

// The chart's faces split at the area median along the principal axis of their flattened centroids
// (area weighted); each half then goes through `splitter` (a half that is not a disk is split until
// its parts are). One part only when the chart cannot be halved.
std::vector<Chart> halve_chart(const Chart& chart, const FlatChart& flat, ChartSplitter& splitter);

}  // namespace exitance::uvgen
