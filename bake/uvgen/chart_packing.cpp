#include "chart_packing.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace exitance::uvgen {
namespace {

// Andrew's monotone chain; collinear points dropped. Fewer than three points come back as they are.
std::vector<Point2> convex_hull(std::vector<Point2> points) {
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  auto turn = [](const Point2& o, const Point2& a, const Point2& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  std::vector<Point2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

struct Orientation {
  double cos_angle = 1, sin_angle = 0;
  Point2 min{}, extent{};
};

Orientation orient(const std::vector<Point2>& hull, double angle) {
  Orientation o{std::cos(angle), std::sin(angle), {1e300, 1e300}, {}};
  Point2 max{-1e300, -1e300};
  for (const Point2& p : hull) {
    const double x = p[0] * o.cos_angle - p[1] * o.sin_angle, y = p[0] * o.sin_angle + p[1] * o.cos_angle;
    o.min = {std::min(o.min[0], x), std::min(o.min[1], y)};
    max = {std::max(max[0], x), std::max(max[1], y)};
  }
  if (hull.empty()) return {1, 0, {0, 0}, {0, 0}};
  o.extent = {max[0] - o.min[0], max[1] - o.min[1]};
  return o;
}

// The rotation whose bounding box has the least area (one of the hull's edges lies on it), turned so
// that the box is at least as wide as it is tall.
Orientation minimal_area_orientation(const ChartOutline& chart) {
  const std::vector<Point2> hull = convex_hull(chart.points);
  double best_angle = 0, best_area = 1e300;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Point2 &a = hull[i], &b = hull[(i + 1) % hull.size()];
    const double angle = -std::atan2(b[1] - a[1], b[0] - a[0]);
    const Orientation o = orient(hull, angle);
    const double area = o.extent[0] * o.extent[1];
    if (area < best_area * (1 - 1e-9)) best_area = area, best_angle = angle;
  }
  Orientation o = orient(hull, best_angle);
  if (o.extent[1] > o.extent[0]) o = orient(hull, best_angle + 0.5 * std::numbers::pi);
  return o;
}

struct Box {
  int width, height;
  size_t chart;
};

struct Segment {
  int x, y, width;
};

struct StripResult {
  std::vector<std::array<int, 2>> position;  // per box, in sorted-box order
  std::vector<uint8_t> turned;
  int width = 0, height = 0;
};

// Bottom-left skyline packing into a strip `strip_width` wide; each box goes where its top is lowest
// (then leftmost), turned by 90 degrees when that is lower.
StripResult pack_strip(const std::vector<Box>& boxes, int strip_width) {
  StripResult result;
  result.position.resize(boxes.size());
  result.turned.resize(boxes.size());
  std::vector<Segment> skyline{{0, 0, strip_width}};
  for (size_t b = 0; b < boxes.size(); ++b) {
    int best_top = INT32_MAX, best_x = 0, best_y = 0, best_w = 0;
    bool best_turned = false;
    for (int turned = 0; turned < 2; ++turned) {
      const int w = turned ? boxes[b].height : boxes[b].width, h = turned ? boxes[b].width : boxes[b].height;
      if (w > strip_width || (turned && w == h)) continue;
      for (size_t i = 0; i < skyline.size(); ++i) {
        const int x = skyline[i].x;
        if (x + w > strip_width) break;
        int y = 0;
        for (size_t j = i; j < skyline.size() && skyline[j].x < x + w; ++j) y = std::max(y, skyline[j].y);
        if (y + h < best_top || (y + h == best_top && x < best_x)) {
          best_top = y + h, best_x = x, best_y = y, best_w = w, best_turned = turned;
        }
      }
    }
    result.position[b] = {best_x, best_y};
    result.turned[b] = best_turned;
    result.width = std::max(result.width, best_x + best_w);
    result.height = std::max(result.height, best_top);
    // The skyline under the box rises to its top.
    std::vector<Segment> next;
    next.reserve(skyline.size() + 2);
    const Segment placed{best_x, best_top, best_w};
    const int end = best_x + best_w;
    bool inserted = false;
    for (const Segment& s : skyline) {
      const int s_end = s.x + s.width;
      if (s_end <= best_x) {
        next.push_back(s);
        continue;
      }
      if (s.x >= end) {
        if (!inserted) next.push_back(placed), inserted = true;
        next.push_back(s);
        continue;
      }
      if (s.x < best_x) next.push_back({s.x, s.y, best_x - s.x});
      if (!inserted) next.push_back(placed), inserted = true;
      if (s_end > end) next.push_back({end, s.y, s_end - end});
    }
    if (!inserted) next.push_back(placed);
    skyline.clear();
    for (const Segment& s : next) {
      if (!skyline.empty() && skyline.back().y == s.y && skyline.back().x + skyline.back().width == s.x)
        skyline.back().width += s.width;
      else
        skyline.push_back(s);
    }
  }
  return result;
}

}  // namespace

Point2 PackedCharts::uv(size_t chart, Point2 point) const {
  const ChartPlacement& c = placements[chart];
  double x = (point[0] * c.cos_angle - point[1] * c.sin_angle - c.min_after_rotation[0]) * texels_per_unit;
  double y = (point[0] * c.sin_angle + point[1] * c.cos_angle - c.min_after_rotation[1]) * texels_per_unit;
  if (c.quarter_turn) {
    const double turned_x = c.extent[1] * texels_per_unit - y;
    y = x;
    x = turned_x;
  }
  const double side = double(std::max(width, height));
  return {std::clamp((c.origin[0] + x) / side, 0.0, 1.0), std::clamp((c.origin[1] + y) / side, 0.0, 1.0)};
}

PackedCharts pack_charts(const std::vector<ChartOutline>& charts, const PackingSettings& settings) {
  PackedCharts packed;
  packed.placements.resize(charts.size());
  for (size_t c = 0; c < charts.size(); ++c) {
    const Orientation o = minimal_area_orientation(charts[c]);
    ChartPlacement& p = packed.placements[c];
    p.cos_angle = o.cos_angle;
    p.sin_angle = o.sin_angle;
    p.min_after_rotation = o.min;
    p.extent = o.extent;
  }
  const double gutter = settings.gutter_texels;
  const int max_side = std::max(settings.max_side_texels, 1);
  double density = settings.texels_per_unit;
  for (int attempt = 0;; ++attempt) {
    // Each chart's box: the chart plus half the gutter on every side, whole texels.
    std::vector<Box> boxes(charts.size());
    double box_area = 0;
    int narrowest_fit = 1;
    for (size_t c = 0; c < charts.size(); ++c) {
      const Point2& e = packed.placements[c].extent;
      boxes[c] = {std::max(1, int(std::ceil(e[0] * density + gutter))), std::max(1, int(std::ceil(e[1] * density + gutter))), c};
      box_area += double(boxes[c].width) * boxes[c].height;
      narrowest_fit = std::max(narrowest_fit, std::min(boxes[c].width, boxes[c].height));
    }
    std::sort(boxes.begin(), boxes.end(), [](const Box& a, const Box& b) {
      if (a.height != b.height) return a.height > b.height;
      if (a.width != b.width) return a.width > b.width;
      return a.chart < b.chart;
    });
    // A few strip widths around the square; keep the smallest rectangle that fits the page.
    StripResult best;
    bool have_best = false, best_fits = false;
    for (double factor : {1.0, 1.1, 1.25, 1.5, 2.0}) {
      const int strip = std::max(narrowest_fit, int(std::ceil(std::sqrt(box_area) * factor)));
      StripResult r = pack_strip(boxes, strip);
      const bool fits = std::max(r.width, r.height) <= max_side;
      const double area = double(r.width) * r.height, best_area = double(best.width) * best.height;
      const bool better = !have_best || (fits && !best_fits) ||
                          (fits == best_fits && (area < best_area || (area == best_area &&
                                                 std::max(r.width, r.height) < std::max(best.width, best.height))));
      if (better) best = std::move(r), have_best = true, best_fits = fits;
    }
    const bool smallest = density * std::max(1e-300, [&] {
      double largest = 0;
      for (const ChartPlacement& p : packed.placements) largest = std::max({largest, p.extent[0], p.extent[1]});
      return largest;
    }()) < 0.5;
    if (best_fits || attempt >= 60 || smallest) {
      packed.fits = best_fits;
      packed.width = std::max(best.width, 1);
      packed.height = std::max(best.height, 1);
      packed.texels_per_unit = density;
      for (size_t b = 0; b < boxes.size(); ++b) {
        ChartPlacement& p = packed.placements[boxes[b].chart];
        p.quarter_turn = best.turned[b];
        p.origin = {best.position[b][0] + 0.5 * gutter, best.position[b][1] + 0.5 * gutter};
      }
      return packed;
    }
    // Too big for the page: lower the density (the gutters do not shrink, so shrink a bit more).
    density *= std::min(0.95, 0.97 * double(max_side) / double(std::max(best.width, best.height)));
  }
}

}  // namespace exitance::uvgen
