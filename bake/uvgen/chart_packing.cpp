#include "chart_packing.h"

#include <algorithm>
#include <bit>
#include <cstdint>
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

// A turned mask as bit rows for the bottom-left search: its own texels (tested against the grid)
// and its texels dilated by the gutter in every direction (stamped into the grid once placed).
struct BitMask {
  int width = 0, height = 0, words = 0;  // `words` 64-bit words per row of the own texels
  std::vector<uint64_t> rows;            // height x words
  int dilated_words = 0;                 // per row of the dilated mask: width + 2 dilation bits
  std::vector<uint64_t> dilated_rows;    // (height + 2 dilation) x dilated_words
  int key_row = 0, key_start = 0, key_length = 0;  // the longest run of texels in one row
  std::vector<std::array<int, 2>> first_run;       // per row: start and length of its first run of texels
};

void set_bit(std::vector<uint64_t>& bits, size_t row_start, int x) { bits[row_start + size_t(x >> 6)] |= uint64_t(1) << (x & 63); }

BitMask bit_mask_of(const ChartMask& m, int dilation) {
  BitMask b;
  b.width = m.width;
  b.height = m.height;
  b.words = (m.width + 63) / 64;
  b.rows.assign(size_t(b.height) * size_t(b.words), 0);
  const int dilated_width = m.width + 2 * dilation, dilated_height = m.height + 2 * dilation;
  b.dilated_words = (dilated_width + 63) / 64;
  b.dilated_rows.assign(size_t(dilated_height) * size_t(b.dilated_words), 0);
  // Dilate rows first (each texel widened to 2 dilation + 1), then columns.
  std::vector<uint8_t> wide(size_t(m.height) * size_t(dilated_width), 0);
  b.first_run.assign(size_t(m.height), {0, 0});
  for (int y = 0; y < m.height; ++y) {
    int run = 0;
    bool first_run_ended = false;
    for (int x = 0; x < m.width; ++x) {
      if (!m.at(x, y)) {
        first_run_ended |= run > 0;
        run = 0;
        continue;
      }
      if (!first_run_ended) {
        if (run == 0) b.first_run[size_t(y)][0] = x;
        b.first_run[size_t(y)][1] = run + 1;
      }
      set_bit(b.rows, size_t(y) * size_t(b.words), x);
      if (++run > b.key_length) b.key_length = run, b.key_row = y, b.key_start = x - run + 1;
      for (int d = 0; d <= 2 * dilation; ++d) wide[size_t(y) * size_t(dilated_width) + size_t(x + d)] = 1;
    }
  }
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < dilated_width; ++x)
      if (wide[size_t(y) * size_t(dilated_width) + size_t(x)])
        for (int d = 0; d <= 2 * dilation; ++d) set_bit(b.dilated_rows, size_t(y + d) * size_t(b.dilated_words), x);
  return b;
}

// Texel occupancy of the strip (placed charts dilated by the gutter), one bit per texel, rows
// added as the packing grows upwards.
class OccupancyGrid {
 public:
  explicit OccupancyGrid(int width) : width_(width), words_((width + 63) / 64 + 1) {}

  // The 64 bits of row `y` from column `x` (zero past the top; the padding word keeps x + 64 in range).
  uint64_t bits_at(int y, int x) const {
    if (y >= rows()) return 0;
    const uint64_t* row = &bits_[size_t(y) * size_t(words_)];
    const int word = x >> 6, shift = x & 63;
    return shift == 0 ? row[word] : (row[word] >> shift) | (row[word + 1] << (64 - shift));
  }

  // 0 when the mask at (x, y) overlaps no occupied texel, else how far right the next position
  // that can fit lies: an occupied run met by a row's first run of texels rules out every position
  // until that run is passed.
  int collision_skip(const BitMask& m, int x, int y) const {
    auto row_skip = [&](int r) {
      if (y + r >= rows() || m.first_run[size_t(r)][1] == 0) return 0;
      const int start = x + m.first_run[size_t(r)][0];
      const int occupied = next_set(y + r, start);
      if (occupied < start + m.first_run[size_t(r)][1]) return next_clear(y + r, occupied) - start;
      for (int k = 0; k < m.words; ++k)
        if (bits_at(y + r, x + 64 * k) & m.rows[size_t(r) * size_t(m.words) + size_t(k)]) return 1;
      return 0;
    };
    // The key row first: it fails most often.
    for (int r = m.key_row; r < m.height; ++r)
      if (const int skip = row_skip(r)) return skip;
    for (int r = 0; r < m.key_row; ++r)
      if (const int skip = row_skip(r)) return skip;
    return 0;
  }

  // Free runs [start, end) of row `y` of at least `length` texels, in order.
  template <typename Visit>
  bool for_each_free_run(int y, int length, Visit&& visit) const {
    if (y < rows() && longest_free_[size_t(y)] < length) return false;
    int x = 0;
    while (x < width_) {
      const int free_end = next_set(y, x);  // first occupied at or after x
      if (free_end - x >= length && visit(x, free_end)) return true;
      if (free_end >= width_) break;
      x = next_clear(y, free_end);
    }
    return false;
  }

  void stamp(const BitMask& m, int x, int y, int dilation) {
    const int dilated_height = m.height + 2 * dilation, dilated_width = m.width + 2 * dilation;
    const int top = y + m.height + dilation;
    if (top > rows()) {
      bits_.resize(size_t(top) * size_t(words_), 0);
      longest_free_.resize(size_t(top), width_);
    }
    for (int r = 0; r < dilated_height; ++r) {
      const int gy = y + r - dilation;
      if (gy < 0) continue;
      for (int c = 0; c < dilated_width; ++c) {
        const int gx = x + c - dilation;
        if (gx < 0 || gx >= width_) continue;
        if (m.dilated_rows[size_t(r) * size_t(m.dilated_words) + size_t(c >> 6)] >> (c & 63) & 1)
          set_bit(bits_, size_t(gy) * size_t(words_), gx);
      }
      longest_free_[size_t(gy)] = longest_free_run(gy);
    }
  }

  int rows() const { return int(bits_.size() / size_t(words_)); }

  int next_set(int y, int x) const {
    if (y >= rows()) return width_;
    const uint64_t* row = &bits_[size_t(y) * size_t(words_)];
    for (int word = x >> 6; word * 64 < width_; ++word) {
      uint64_t w = row[word];
      if (word == x >> 6) w &= ~uint64_t(0) << (x & 63);
      if (w) return std::min(width_, word * 64 + std::countr_zero(w));
    }
    return width_;
  }
  int next_clear(int y, int x) const {
    if (y >= rows()) return x;
    const uint64_t* row = &bits_[size_t(y) * size_t(words_)];
    for (int word = x >> 6; word * 64 < width_; ++word) {
      uint64_t w = ~row[word];
      if (word == x >> 6) w &= ~uint64_t(0) << (x & 63);
      if (w) return std::min(width_, word * 64 + std::countr_zero(w));
    }
    return width_;
  }

 private:
  int longest_free_run(int y) const {
    int longest = 0;
    for (int x = 0; x < width_;) {
      const int end = next_set(y, x);
      longest = std::max(longest, end - x);
      if (end >= width_) break;
      x = next_clear(y, end);
    }
    return longest;
  }

  int width_, words_;
  std::vector<uint64_t> bits_;
  std::vector<int> longest_free_;  // per row: the longest run of free texels, to skip rows fast
};

struct StripResult {
  std::vector<std::array<int, 2>> position;  // per chart
  std::vector<int> turns;
  int width = 0, height = 0;
};

// The lowest, then leftmost position where the mask overlaps no occupied texel: rows bottom up, and
// in each row only the columns where the mask's longest run lies in a free run of the grid.
std::array<int, 2> bottom_left_position(const OccupancyGrid& grid, const BitMask& m, int strip_width) {
  std::array<int, 2> found{-1, -1};
  for (int y = 0;; ++y) {
    const bool searched = grid.for_each_free_run(y + m.key_row, m.key_length, [&](int start, int end) {
      const int first = std::max(0, start - m.key_start);
      const int last = std::min(strip_width - m.width, end - m.key_length - m.key_start);
      for (int x = first; x <= last;) {
        const int skip = grid.collision_skip(m, x, y);
        if (skip == 0) {
          found = {x, y};
          return true;
        }
        x += skip;
      }
      return false;
    });
    if (searched) return found;
    if (y >= grid.rows()) return found;  // wider than the strip: no position in empty rows either
  }
}

// Charts in `order` placed one by one by bottom-left fill on the strip's texel occupancy, each in
// the turn whose bottom-left position ends lowest (then lowest, leftmost, fewest turns), or with
// `least_growth` first the one that grows the packed rectangle least: a chart can nest inside
// another's arch, which a skyline cannot reach.
StripResult pack_strip(const std::vector<std::array<BitMask, 4>>& masks, const std::vector<size_t>& order,
                       int strip_width, int dilation, int turn_choices, bool least_growth) {
  StripResult result;
  result.position.resize(masks.size());
  result.turns.resize(masks.size());
  OccupancyGrid grid(strip_width);
  for (size_t chart : order) {
    int best_top = INT32_MAX, best_x = 0, best_y = 0, best_turns = -1;
    int64_t best_area = INT64_MAX;
    for (int turns = 0; turns < turn_choices; ++turns) {
      const BitMask& m = masks[chart][size_t(turns)];
      if (m.width > strip_width) continue;
      const auto [x, y] = bottom_left_position(grid, m, strip_width);
      if (y < 0) continue;
      const int top = y + m.height;
      const int64_t area =
          least_growth ? int64_t(std::max(result.width, x + m.width)) * std::max(result.height, top) : 0;
      if (area < best_area || (area == best_area && (top < best_top || (top == best_top && (y < best_y || (y == best_y && x < best_x))))))
        best_area = area, best_top = top, best_x = x, best_y = y, best_turns = turns;
    }
    if (best_turns < 0) return {};  // wider than the strip in every turn
    const BitMask& m = masks[chart][size_t(best_turns)];
    grid.stamp(m, best_x, best_y, dilation);
    result.position[chart] = {best_x, best_y};
    result.turns[chart] = best_turns;
    result.width = std::max(result.width, best_x + m.width);
    result.height = std::max(result.height, best_y + m.height);
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

double bounding_box_fill(const ChartOutline& chart) {
  double area = 0;
  for (size_t i = 0; i + 2 < chart.points.size(); i += 3) {
    const Point2 &a = chart.points[i], &b = chart.points[i + 1], &c = chart.points[i + 2];
    area += 0.5 * std::fabs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
  }
  const Orientation o = minimal_area_orientation(chart);
  const double box = o.extent[0] * o.extent[1];
  return box > 0 ? area / box : 1;
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
    std::vector<std::array<BitMask, 4>> masks(charts.size());
    std::vector<size_t> mask_area(charts.size());
    double total_area = 0;
    int widest_needed = 1;
    for (size_t c = 0; c < charts.size(); ++c) {
      ChartPlacement& p = packed.placements[c];
      const ChartMask mask = rasterize_chart(charts[c], p, density, grow);
      p.mask_width = mask.width;
      p.mask_height = mask.height;
      for (int turns = 0; turns < turn_choices; ++turns)
        masks[c][size_t(turns)] = bit_mask_of(turned(mask, turns), dilation);
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
    // Neither turn choice wins everywhere (the least growth fills small sets of charts better, the
    // lowest top some tori): both, for every width.
    for (const bool least_growth : {true, false})
    for (double factor : {0.8, 0.9, 1.0, 1.15, 1.3, 1.6}) {
      const int strip = std::max(widest_needed, int(std::ceil(std::sqrt(total_area) * factor)));
      StripResult r = pack_strip(masks, order, strip, dilation, turn_choices, least_growth);
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
