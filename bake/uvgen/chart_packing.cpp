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

// A chart's texels at one density: row-major mask, true where a triangle (grown by `grow` texels)
// touches the texel.
struct ChartMask {
  int width = 0, height = 0;
  std::vector<uint8_t> texels;
  bool at(int x, int y) const { return texels[size_t(y) * size_t(width) + size_t(x)] != 0; }
};

// Separating-axis test of a triangle against the texel [x, x+1] x [y, y+1] grown by `grow`.
bool touches(const std::array<Point2, 3>& p, int x, int y, double grow) {
  auto separated = [&](double ax, double ay) {
    double lo = 1e300, hi = -1e300;
    for (const Point2& q : p) lo = std::min(lo, ax * q[0] + ay * q[1]), hi = std::max(hi, ax * q[0] + ay * q[1]);
    const double centre = ax * (x + 0.5) + ay * (y + 0.5);
    const double radius = (0.5 + grow) * (std::fabs(ax) + std::fabs(ay));
    return hi < centre - radius || lo > centre + radius;
  };
  if (separated(1, 0) || separated(0, 1)) return false;
  for (int k = 0; k < 3; ++k) {
    const Point2 &a = p[size_t(k)], &b = p[size_t(k + 1) % 3];
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    const double length = std::sqrt(ex * ex + ey * ey);
    if (length > 0 && separated(-ey / length, ex / length)) return false;
  }
  return true;
}

// Chart points in texels after the placement's rotation and minimum, before the quarter turns.
Point2 to_texels(const ChartPlacement& c, Point2 point, double density) {
  return {(point[0] * c.cos_angle - point[1] * c.sin_angle - c.min_after_rotation[0]) * density,
          (point[0] * c.sin_angle + point[1] * c.cos_angle - c.min_after_rotation[1]) * density};
}

ChartMask rasterize_chart(const ChartOutline& chart, const ChartPlacement& placement, double density, double grow) {
  ChartMask mask;
  mask.width = std::max(1, int(std::floor(placement.extent[0] * density + grow)) + 1);
  mask.height = std::max(1, int(std::floor(placement.extent[1] * density + grow)) + 1);
  mask.texels.assign(size_t(mask.width) * size_t(mask.height), 0);
  for (size_t i = 0; i + 2 < chart.points.size(); i += 3) {
    std::array<Point2, 3> p;
    for (size_t k = 0; k < 3; ++k) p[k] = to_texels(placement, chart.points[i + k], density);
    const int x0 = std::max(0, int(std::floor(std::min({p[0][0], p[1][0], p[2][0]}) - grow)));
    const int x1 = std::min(mask.width - 1, int(std::floor(std::max({p[0][0], p[1][0], p[2][0]}) + grow)));
    const int y0 = std::max(0, int(std::floor(std::min({p[0][1], p[1][1], p[2][1]}) - grow)));
    const int y1 = std::min(mask.height - 1, int(std::floor(std::max({p[0][1], p[1][1], p[2][1]}) + grow)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        if (!mask.at(x, y) && touches(p, x, y, grow)) mask.texels[size_t(y) * size_t(mask.width) + size_t(x)] = 1;
  }
  return mask;
}

// The mask turned by `turns` quarter turns counter-clockwise: texel (x, y) goes to
// (h-1-y, x), (w-1-x, h-1-y) or (y, w-1-x), matching PackedCharts::uv's continuous turns.
ChartMask turned(const ChartMask& m, int turns) {
  if (turns == 0) return m;
  ChartMask t;
  t.width = turns % 2 ? m.height : m.width;
  t.height = turns % 2 ? m.width : m.height;
  t.texels.assign(m.texels.size(), 0);
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      if (!m.at(x, y)) continue;
      int tx = 0, ty = 0;
      if (turns == 1)
        tx = m.height - 1 - y, ty = x;
      else if (turns == 2)
        tx = m.width - 1 - x, ty = m.height - 1 - y;
      else
        tx = y, ty = m.width - 1 - x;
      t.texels[size_t(ty) * size_t(t.width) + size_t(tx)] = 1;
    }
  return t;
}

// What the skyline needs of a turned mask: per column its lowest texel (or none), and per column of
// the mask widened by the dilation its dilated top (one past the highest texel, plus the dilation).
struct Profile {
  int width = 0, height = 0;
  std::vector<int> bottom;       // per column; INT32_MAX when the column is empty
  std::vector<int> dilated_top;  // per column x - dilation .. width - 1 + dilation; INT32_MIN when empty
};

Profile profile_of(const ChartMask& m, int dilation) {
  Profile p;
  p.width = m.width;
  p.height = m.height;
  p.bottom.assign(size_t(m.width), INT32_MAX);
  std::vector<int> top(size_t(m.width), INT32_MIN);
  for (int x = 0; x < m.width; ++x)
    for (int y = 0; y < m.height; ++y)
      if (m.at(x, y)) {
        p.bottom[size_t(x)] = std::min(p.bottom[size_t(x)], y);
        top[size_t(x)] = y + 1;
      }
  p.dilated_top.assign(size_t(m.width + 2 * dilation), INT32_MIN);
  for (int x = 0; x < m.width; ++x)
    if (top[size_t(x)] != INT32_MIN)
      for (int d = 0; d <= 2 * dilation; ++d)
        p.dilated_top[size_t(x + d)] = std::max(p.dilated_top[size_t(x + d)], top[size_t(x)] + dilation);
  return p;
}

struct StripResult {
  std::vector<std::array<int, 2>> position;  // per chart
  std::vector<int> turns;
  int width = 0, height = 0;
};

// Charts in `order` dropped one by one onto a skyline `strip_width` texels wide, each at the column
// and turn where its top ends lowest (then leftmost, then fewest turns).
StripResult pack_strip(const std::vector<std::array<Profile, 4>>& profiles, const std::vector<size_t>& order,
                       int strip_width, int dilation, int turn_choices) {
  StripResult result;
  result.position.resize(profiles.size());
  result.turns.resize(profiles.size());
  std::vector<int> skyline(size_t(strip_width), 0);
  for (size_t chart : order) {
    int best_top = INT32_MAX, best_x = 0, best_y = 0, best_turns = 0;
    int64_t best_waste = INT64_MAX;
    for (int turns = 0; turns < turn_choices; ++turns) {
      const Profile& p = profiles[chart][size_t(turns)];
      for (int x = 0; x + p.width <= strip_width; ++x) {
        int y = 0;
        for (int c = 0; c < p.width; ++c)
          if (p.bottom[size_t(c)] != INT32_MAX) y = std::max(y, skyline[size_t(x + c)] - p.bottom[size_t(c)]);
        if (y + p.height > best_top) continue;
        // Equal tops: the least area left unreachable under the chart (an arch opening up, not down,
        // so later charts can fill it).
        int64_t waste = 0;
        for (int c = 0; c < p.width; ++c)
          if (p.bottom[size_t(c)] != INT32_MAX) waste += y + p.bottom[size_t(c)] - skyline[size_t(x + c)];
        if (y + p.height < best_top || waste < best_waste)
          best_top = y + p.height, best_waste = waste, best_x = x, best_y = y, best_turns = turns;
      }
    }
    if (best_top == INT32_MAX) return {};  // wider than the strip in every turn
    const Profile& p = profiles[chart][size_t(best_turns)];
    for (int c = 0; c < int(p.dilated_top.size()); ++c) {
      const int column = best_x + c - dilation;
      if (column < 0 || column >= strip_width || p.dilated_top[size_t(c)] == INT32_MIN) continue;
      skyline[size_t(column)] = std::max(skyline[size_t(column)], best_y + p.dilated_top[size_t(c)]);
    }
    result.position[chart] = {best_x, best_y};
    result.turns[chart] = best_turns;
    result.width = std::max(result.width, best_x + p.width);
    result.height = std::max(result.height, best_top);
  }
  return result;
}

}  // namespace

Point2 PackedCharts::uv(size_t chart, Point2 point) const {
  const ChartPlacement& c = placements[chart];
  const Point2 t = to_texels(c, point, texels_per_unit);
  const double w = c.mask_width, h = c.mask_height;
  Point2 turned_point = t;
  if (c.quarter_turns == 1)
    turned_point = {h - t[1], t[0]};
  else if (c.quarter_turns == 2)
    turned_point = {w - t[0], h - t[1]};
  else if (c.quarter_turns == 3)
    turned_point = {t[1], w - t[0]};
  const double side = double(std::max(width, height));
  return {std::clamp((c.origin[0] + turned_point[0]) / side, 0.0, 1.0),
          std::clamp((c.origin[1] + turned_point[1]) / side, 0.0, 1.0)};
}

PackedCharts pack_charts(const std::vector<ChartOutline>& charts, const PackingSettings& settings) {
  PackedCharts packed;
  packed.placements.resize(charts.size());
  double largest_extent = 0;
  for (size_t c = 0; c < charts.size(); ++c) {
    const Orientation o = minimal_area_orientation(charts[c]);
    ChartPlacement& p = packed.placements[c];
    p.cos_angle = o.cos_angle;
    p.sin_angle = o.sin_angle;
    p.min_after_rotation = o.min;
    p.extent = o.extent;
    largest_extent = std::max({largest_extent, o.extent[0], o.extent[1]});
  }
  const int dilation = std::max(0, int(std::ceil(settings.gutter_texels)) - 1);
  const double grow = std::max(0.0, 0.5 * (settings.gutter_texels - dilation));
  // Four turns let charts nest; with many charts two keep the cost of the column scan down.
  const int turn_choices = charts.size() <= 256 ? 4 : 2;
  const int max_side = std::max(settings.max_side_texels, 1);
  // One packing at `density`: the best strip, and the charts' mask sizes at that density.
  struct Attempt {
    StripResult best;
    bool packed = false, fits = false;
  };
  double chart_area = 0;  // 3-D-area units
  for (const ChartOutline& chart : charts)
    for (size_t i = 0; i + 2 < chart.points.size(); i += 3) {
      const Point2 &a = chart.points[i], &b = chart.points[i + 1], &c = chart.points[i + 2];
      chart_area += 0.5 * std::fabs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    }
  auto pack_at = [&](double density) {
    // The charts' own texels alone exceed the page: not worth rasterizing (it is slow at a density
    // far too high).
    if (chart_area * density * density > double(max_side) * max_side) return Attempt{};
    std::vector<std::array<Profile, 4>> profiles(charts.size());
    std::vector<size_t> mask_area(charts.size());
    double total_area = 0;
    int widest_needed = 1;
    for (size_t c = 0; c < charts.size(); ++c) {
      ChartPlacement& p = packed.placements[c];
      const ChartMask mask = rasterize_chart(charts[c], p, density, grow);
      p.mask_width = mask.width;
      p.mask_height = mask.height;
      for (int turns = 0; turns < turn_choices; ++turns)
        profiles[c][size_t(turns)] = profile_of(turned(mask, turns), dilation);
      mask_area[c] = size_t(std::count(mask.texels.begin(), mask.texels.end(), uint8_t(1)));
      total_area += double(mask.width + dilation) * double(mask.height + dilation);
      widest_needed = std::max(widest_needed, std::min(mask.width, mask.height));
    }
    std::vector<size_t> order(charts.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      const int ha = std::min(packed.placements[a].mask_width, packed.placements[a].mask_height);
      const int hb = std::min(packed.placements[b].mask_width, packed.placements[b].mask_height);
      return mask_area[a] != mask_area[b] ? mask_area[a] > mask_area[b] : ha > hb;
    });
    // A few strip widths around the square; keep the smallest rectangle that fits the page.
    StripResult best;
    bool have_best = false, best_fits = false;
    for (double factor : {0.8, 0.9, 1.0, 1.15, 1.3, 1.6}) {
      const int strip = std::max(widest_needed, int(std::ceil(std::sqrt(total_area) * factor)));
      StripResult r = pack_strip(profiles, order, strip, dilation, turn_choices);
      if (r.position.empty()) continue;
      const bool fits = std::max(r.width, r.height) <= max_side;
      const double area = double(r.width) * r.height, best_area = double(best.width) * best.height;
      const bool better = !have_best || (fits && !best_fits) ||
                          (fits == best_fits &&
                           (area < best_area ||
                            (area == best_area && std::max(r.width, r.height) < std::max(best.width, best.height))));
      if (better) best = std::move(r), have_best = true, best_fits = fits;
    }
    return Attempt{std::move(best), have_best, best_fits};
  };
  auto commit = [&](double density) {
    Attempt a = pack_at(density);
    packed.fits = a.fits;
    packed.width = std::max(a.best.width, 1);
    packed.height = std::max(a.best.height, 1);
    packed.texels_per_unit = density;
    for (size_t c = 0; c < charts.size(); ++c) {
      ChartPlacement& p = packed.placements[c];
      p.quarter_turns = a.packed ? a.best.turns[c] : 0;
      p.origin = a.packed ? Point2{double(a.best.position[c][0]), double(a.best.position[c][1])} : Point2{0, 0};
    }
    return packed;
  };
  auto side_of = [&](const Attempt& a, double density) {
    return a.packed ? double(std::max(a.best.width, a.best.height))
                    : std::max(2.0 * max_side, std::sqrt(chart_area) * density);
  };

  // Every chart takes at least (1 + dilation)^2 texels whatever the density: when that is more than
  // the page, no density keeps the gutter; pack once, the charts' own area about half the page.
  const double first = settings.texels_per_unit;
  if (double(charts.size()) * (1.0 + dilation) * (1.0 + dilation) > double(max_side) * max_side) {
    const double fitting = chart_area > 0 ? std::sqrt(0.5 * double(max_side) * max_side / chart_area) : first;
    PackedCharts result = commit(std::min(first, fitting));
    result.fits = false;
    return result;
  }
  Attempt attempt = pack_at(first);
  if (attempt.fits) return commit(first);
  // Too big for the page: shrink (at least halving) until it fits, then bisect between the two.
  double too_big = first, fitting = 0;
  for (int step = 0; step < 40; ++step) {
    const double next = too_big * std::min(0.5, 0.97 * double(max_side) / side_of(attempt, too_big));
    if (next * largest_extent < 0.05) break;
    attempt = pack_at(next);
    if (attempt.fits) {
      fitting = next;
      break;
    }
    too_big = next;
  }
  if (fitting == 0) {  // nothing fitted: the smallest tried, marked as not fitting
    PackedCharts result = commit(too_big);
    result.fits = false;
    return result;
  }
  for (int step = 0; step < 6; ++step) {  // the largest fitting density within about 3 %
    const double middle = std::sqrt(fitting * too_big);
    if (pack_at(middle).fits)
      fitting = middle;
    else
      too_big = middle;
  }
  return commit(fitting);
}

}  // namespace exitance::uvgen
