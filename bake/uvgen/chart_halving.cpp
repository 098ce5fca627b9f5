#include "chart_halving.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace exitance::uvgen {

std::vector<Chart> halve_chart(const Chart& chart, const FlatChart& flat, ChartSplitter& splitter) {
  const size_t count = chart.triangles.size();
  std::vector<Point2> centre(count);
  std::vector<double> weight(count);
  double total = 0, mean_x = 0, mean_y = 0;
  for (size_t i = 0; i < count; ++i) {
    const auto& q = flat.corner_uv[i];
    centre[i] = {(q[0][0] + q[1][0] + q[2][0]) / 3, (q[0][1] + q[1][1] + q[2][1]) / 3};
    weight[i] = 0.5 * std::fabs((q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]));
    total += weight[i], mean_x += weight[i] * centre[i][0], mean_y += weight[i] * centre[i][1];
  }
  if (count < 2 || !(total > 0)) return {chart};
  mean_x /= total, mean_y /= total;
  double xx = 0, xy = 0, yy = 0;
  for (size_t i = 0; i < count; ++i) {
    const double dx = centre[i][0] - mean_x, dy = centre[i][1] - mean_y;
    xx += weight[i] * dx * dx, xy += weight[i] * dx * dy, yy += weight[i] * dy * dy;
  }
  const double angle = 0.5 * std::atan2(2 * xy, xx - yy);  // the major axis of the 2x2 covariance
  const double ax = std::cos(angle), ay = std::sin(angle);
  std::vector<std::pair<double, size_t>> along(count);
  for (size_t i = 0; i < count; ++i) along[i] = {centre[i][0] * ax + centre[i][1] * ay, i};
  std::sort(along.begin(), along.end());  // ties by face position: deterministic
  std::vector<uint8_t> side(count, 1);
  double below = 0;
  for (const auto& entry : along) {
    if (below >= 0.5 * total) break;
    below += weight[entry.second], side[entry.second] = 0;
  }
  Chart halves[2];
  for (size_t i = 0; i < count; ++i) halves[side[i]].triangles.push_back(chart.triangles[i]);  // stays ascending
  std::vector<Chart> parts;
  for (Chart& half : halves) {
    half.normal = chart.normal;
    if (!half.triangles.empty()) splitter.add(std::move(half), parts);
  }
  return parts;
}

}  // namespace exitance::uvgen
