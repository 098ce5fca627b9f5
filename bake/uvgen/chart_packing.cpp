#include "chart_packing.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cmath>
#include <numbers>
#include <mutex>
#include <numeric>
#include <optional>
#include <thread>
#include <tuple>

#include "progress_steps.h"

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

// Separating-axis test of a triangle against texels [x, x+1] x [y, y+1] grown by `grow`: the
// triangle's extent along the two texel axes and its three edge normals, computed once per triangle.
class TriangleTexelTest {
 public:
  TriangleTexelTest(const std::array<Point2, 3>& p, double grow) {
    add(p, grow, 1, 0);
    add(p, grow, 0, 1);
    for (int k = 0; k < 3; ++k) {
      const Point2 &a = p[size_t(k)], &b = p[size_t(k + 1) % 3];
      const double ex = b[0] - a[0], ey = b[1] - a[1];
      const double length = std::sqrt(ex * ex + ey * ey);
      if (length > 0) add(p, grow, -ey / length, ex / length);
    }
  }
  bool touches(int x, int y) const {
    for (int i = 0; i < count_; ++i) {
      const Axis& a = axes_[size_t(i)];
      const double centre = a.ax * (x + 0.5) + a.ay * (y + 0.5);
      if (a.hi < centre - a.radius || a.lo > centre + a.radius) return false;
    }
    return true;
  }

 private:
  struct Axis {
    double ax, ay, lo, hi, radius;
  };
  void add(const std::array<Point2, 3>& p, double grow, double ax, double ay) {
    Axis& a = axes_[size_t(count_++)];
    a = {ax, ay, 1e300, -1e300, (0.5 + grow) * (std::fabs(ax) + std::fabs(ay))};
    for (const Point2& q : p) a.lo = std::min(a.lo, ax * q[0] + ay * q[1]), a.hi = std::max(a.hi, ax * q[0] + ay * q[1]);
  }
  std::array<Axis, 5> axes_{};
  int count_ = 0;
};

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
    const TriangleTexelTest test(p, grow);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        if (!mask.at(x, y) && test.touches(x, y)) mask.texels[size_t(y) * size_t(mask.width) + size_t(x)] = 1;
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

// A turned mask for the bottom-left search: its own texels as runs per row (tested against the
// grid) and its texels dilated by the gutter in every direction as bit rows (stamped into the grid
// once placed).
struct MaskRun {
  int start = 0, length = 0, level = 0;  // level: floor(log2(length)), the grid's run table to read
};

struct BitMask {
  int width = 0, height = 0;
  std::vector<int> row_first;  // height + 1: the runs of row r are runs[row_first[r] .. row_first[r + 1])
  std::vector<MaskRun> runs;
  std::vector<int> order;      // rows with texels, in the order the search tests them
  std::vector<int> row_longest;     // per row: its longest run
  int key_row = 0, key_length = 0;  // the first row holding the longest run, and that run's length
  int longest_run = 0;              // == key_length
  int dilated_words = 0;               // per row of the dilated mask: width + 2 dilation bits
  std::vector<uint64_t> dilated_rows;  // (height + 2 dilation) x dilated_words
};

// Sets bits [start, end) of a row of 64-bit words.
void set_range(uint64_t* row, int start, int end) {
  for (int x = start; x < end;) {
    const int word = x >> 6, shift = x & 63, count = std::min(64 - shift, end - x);
    row[word] |= (count == 64 ? ~uint64_t(0) : ((uint64_t(1) << count) - 1)) << shift;
    x += count;
  }
}

BitMask bit_mask_of(const ChartMask& m, int dilation) {
  BitMask b;
  b.width = m.width;
  b.height = m.height;
  const int dilated_width = m.width + 2 * dilation, dilated_height = m.height + 2 * dilation;
  b.dilated_words = (dilated_width + 63) / 64;
  b.dilated_rows.assign(size_t(dilated_height) * size_t(b.dilated_words), 0);
  b.row_first.assign(size_t(m.height) + 1, 0);
  b.row_longest.assign(size_t(m.height), 0);
  // Each row's runs, and the row widened by 2 dilation texels; then rows dilated upwards.
  std::vector<uint64_t> wide(size_t(m.height) * size_t(b.dilated_words), 0);
  for (int y = 0; y < m.height; ++y) {
    b.row_first[size_t(y)] = int(b.runs.size());
    for (int x = 0; x < m.width;) {
      if (!m.at(x, y)) {
        ++x;
        continue;
      }
      int end = x;
      while (end < m.width && m.at(end, y)) ++end;
      b.runs.push_back({x, end - x, int(std::bit_width(unsigned(end - x))) - 1});
      if (end - x > b.key_length) b.key_length = end - x, b.key_row = y;
      b.row_longest[size_t(y)] = std::max(b.row_longest[size_t(y)], end - x);
      set_range(&wide[size_t(y) * size_t(b.dilated_words)], x, end + 2 * dilation);
      x = end;
    }
  }
  b.row_first[size_t(m.height)] = int(b.runs.size());
  b.longest_run = b.key_length;
  for (int y = 0; y < m.height; ++y)
    for (int d = 0; d <= 2 * dilation; ++d)
      for (int w = 0; w < b.dilated_words; ++w)
        b.dilated_rows[size_t(y + d) * size_t(b.dilated_words) + size_t(w)] |= wide[size_t(y) * size_t(b.dilated_words) + size_t(w)];
  // The key row first (it fails most often), then the others spread out (bottom, top, middle,
  // quarters, ...), so that an obstacle anywhere under the mask is met after few rows.
  std::vector<uint8_t> taken(size_t(m.height), 0);
  auto take = [&](int r) {
    if (r < 0 || r >= m.height || taken[size_t(r)]) return;
    taken[size_t(r)] = 1;
    if (b.row_first[size_t(r) + 1] > b.row_first[size_t(r)]) b.order.push_back(r);
  };
  take(b.key_row);
  take(0);
  take(m.height - 1);
  for (int step = std::bit_floor(unsigned(std::max(m.height, 1))); step >= 1; step /= 2)
    for (int r = step; r < m.height; r += 2 * step) take(r);
  for (int r = 0; r < m.height; ++r) take(r);
  return b;
}

// Texel occupancy of the strip (placed charts dilated by the gutter), one bit per texel, rows
// added as the packing grows upwards. Per row also a run table: level k holds, for every column x,
// whether any of the 2^k texels from x on is occupied, so whether a run of length L starting at
// column c overlaps the row is two shifted reads of level floor(log2 L), for 64 columns at a time.
class OccupancyGrid {
 public:
  // `longest_run`: the longest mask run that will be tested (the levels kept).
  OccupancyGrid(int width, int longest_run)
      : width_(width),
        used_words_((width + 63) / 64),
        words_(used_words_ + 1),  // a zero word past the end for the shifted reads
        levels_(int(std::bit_width(unsigned(std::clamp(longest_run, 1, std::max(width, 1)))))) {}

  int width() const { return width_; }
  int rows() const { return int(longest_free_.size()); }
  int longest_free(int y) const { return longest_free_[size_t(y)]; }
  const uint64_t* level(int y, int k) const { return &table_[(size_t(y) * size_t(levels_) + size_t(k)) * size_t(words_)]; }

  // Bits x .. x+63 of a level row, for x + 63 < 64 * words_ (the padding word is zero).
  static uint64_t read(const uint64_t* row, int x) {
    const int word = x >> 6, shift = x & 63;
    return shift == 0 ? row[word] : (row[word] >> shift) | (row[word + 1] << (64 - shift));
  }

  void stamp(const BitMask& m, int x, int y, int dilation) {
    const int dilated_height = m.height + 2 * dilation;
    const int top = y + m.height + dilation;
    if (top > rows()) {
      table_.resize(size_t(top) * size_t(levels_) * size_t(words_), 0);
      longest_free_.resize(size_t(top), width_);
    }
    const int left = x - dilation;  // grid column of the dilated mask's column 0
    for (int r = 0; r < dilated_height; ++r) {
      const int gy = y + r - dilation;
      if (gy < 0) continue;
      uint64_t* row = &table_[size_t(gy) * size_t(levels_) * size_t(words_)];
      const uint64_t* bits = &m.dilated_rows[size_t(r) * size_t(m.dilated_words)];
      for (int w = 0; w < m.dilated_words; ++w) {
        uint64_t word = bits[w];
        if (!word) continue;
        int column = left + 64 * w;
        if (column < 0) {  // drop the bits left of the strip
          if (column <= -64) continue;
          word >>= -column;
          column = 0;
        }
        const int shift = column & 63, target = column >> 6;
        if (target < used_words_) row[target] |= word << shift;
        if (shift && target + 1 < used_words_) row[target + 1] |= word >> (64 - shift);
      }
      if (width_ & 63) row[used_words_ - 1] &= (uint64_t(1) << (width_ & 63)) - 1;  // and right of it
      update_row(gy, std::max(left, 0), std::min(width_, left + 64 * m.dilated_words));
    }
  }

 private:
  // Bits x .. x+63 of a level row, zero past the used words.
  uint64_t read_safe(const uint64_t* row, int x) const {
    const int word = x >> 6, shift = x & 63;
    if (word >= used_words_) return 0;
    uint64_t bits = row[word] >> shift;
    if (shift && word + 1 < used_words_) bits |= row[word + 1] << (64 - shift);
    return bits;
  }

  // Row y's levels after its columns [begin, end) changed: level k changes from 2^k - 1 columns
  // before `begin` on.
  void update_row(int y, int begin, int end) {
    uint64_t* base = &table_[size_t(y) * size_t(levels_) * size_t(words_)];
    const int last_word = std::min(used_words_ - 1, (end - 1) >> 6);
    for (int k = 1; k < levels_; ++k) {
      const uint64_t* below = base + size_t(k - 1) * size_t(words_);
      uint64_t* level = base + size_t(k) * size_t(words_);
      const int half = 1 << (k - 1);
      for (int w = std::max(0, begin - (1 << k) + 1) >> 6; w <= last_word; ++w) level[w] = below[w] | read_safe(below, 64 * w + half);
    }
    int longest = 0;  // the longest run of free texels
    for (int x = 0; x < width_;) {
      const int end = next_set(base, x);
      longest = std::max(longest, end - x);
      if (end >= width_) break;
      x = next_clear(base, end);
    }
    longest_free_[size_t(y)] = longest;
  }

  int next_set(const uint64_t* row, int x) const {
    for (int word = x >> 6; word < used_words_; ++word) {
      uint64_t w = row[word];
      if (word == x >> 6) w &= ~uint64_t(0) << (x & 63);
      if (w) return std::min(width_, word * 64 + std::countr_zero(w));
    }
    return width_;
  }
  int next_clear(const uint64_t* row, int x) const {
    for (int word = x >> 6; word < used_words_; ++word) {
      uint64_t w = ~row[word];
      if (word == x >> 6) w &= ~uint64_t(0) << (x & 63);
      if (w) return std::min(width_, word * 64 + std::countr_zero(w));
    }
    return width_;
  }

  int width_, used_words_, words_, levels_;
  std::vector<uint64_t> table_;    // rows x levels x words
  std::vector<int> longest_free_;  // per row: the longest run of free texels, to skip rows fast
};

struct StripResult {
  std::vector<std::array<int, 2>> position;  // per chart; empty: not packed (see `abandoned`)
  std::vector<int> turns;
  int width = 0, height = 0;
  bool abandoned = false;  // given up part way (it could no longer be the packing kept); else too narrow
};

// The lowest, then leftmost position where the mask overlaps no occupied texel, at most at row
// `y_limit` ({-1, -1} if none). Row by row bottom up, every column at once: a bit set of the
// columns still possible, cleared where a mask run would overlap the grid row under it, until it is
// empty (next row) or every mask row is tested (found). The row that emptied it is tested first at
// the next row: the obstacle is usually still there.
std::array<int, 2> bottom_left_position(const OccupancyGrid& grid, const BitMask& m, int y_limit,
                                        std::vector<uint64_t>& candidates) {
  const int positions = grid.width() - m.width + 1;  // columns 0 .. width - mask width
  const int words = (positions + 63) / 64;
  const uint64_t last_word = positions & 63 ? (uint64_t(1) << (positions & 63)) - 1 : ~uint64_t(0);
  candidates.resize(size_t(words));
  int killer = m.order.empty() ? 0 : m.order.front();
  for (int y = 0; y <= y_limit; ++y) {
    if (y >= grid.rows()) return {0, y};  // nothing placed from here up
    const int key = y + m.key_row, killer_row = y + killer;
    if (key < grid.rows() && grid.longest_free(key) < m.key_length) continue;
    if (killer_row < grid.rows() && grid.longest_free(killer_row) < m.row_longest[size_t(killer)]) continue;
    int lo = 0, hi = words;  // the words that may still hold a candidate
    bool started = false;    // false: every column is still a candidate (`candidates` not written yet)
    auto empties = [&](int r) {
      const int gy = y + r;
      if (gy >= grid.rows()) return false;
      for (int i = m.row_first[size_t(r)]; i < m.row_first[size_t(r) + 1]; ++i) {
        const MaskRun& run = m.runs[size_t(i)];
        const uint64_t* level = grid.level(gy, run.level);
        const int first = run.start, second = run.start + run.length - (1 << run.level);
        if (!started) {
          for (int w = 0; w < words; ++w)
            candidates[size_t(w)] = ~(OccupancyGrid::read(level, 64 * w + first) | OccupancyGrid::read(level, 64 * w + second));
          candidates[size_t(words - 1)] &= last_word;
          started = true;
        } else {
          for (int w = lo; w < hi; ++w)
            candidates[size_t(w)] &= ~(OccupancyGrid::read(level, 64 * w + first) | OccupancyGrid::read(level, 64 * w + second));
        }
        while (lo < hi && !candidates[size_t(lo)]) ++lo;
        while (hi > lo && !candidates[size_t(hi - 1)]) --hi;
        if (lo == hi) return true;
      }
      return false;
    };
    if (empties(killer)) continue;
    bool empty = false;
    for (int r : m.order)
      if (r != killer && empties(r)) {
        killer = r, empty = true;
        break;
      }
    if (!empty) return {started ? 64 * lo + std::countr_zero(candidates[size_t(lo)]) : 0, y};
  }
  return {-1, -1};
}

// Charts in `order` placed one by one by bottom-left fill on the strip's texel occupancy, each in
// the turn whose bottom-left position ends lowest (then lowest, leftmost, fewest turns), or with
// `least_growth` first the one that grows the packed rectangle least: a chart can nest inside
// another's arch, which a skyline cannot reach. A turn's search stops at the row from which it can
// no longer beat the best turn so far. After each chart, `go_on` is asked whether to go on with
// the rectangle packed so far: a strip whose rectangle already loses to another strip's is given up.
template <typename GoOn>
StripResult pack_strip(const std::vector<std::array<BitMask, 4>>& masks, const std::vector<size_t>& order,
                       int strip_width, int dilation, int turn_choices, bool least_growth, GoOn&& go_on) {
  StripResult result;
  result.position.resize(masks.size());
  result.turns.resize(masks.size());
  int longest_run = 1;
  for (const std::array<BitMask, 4>& turns : masks)
    for (int t = 0; t < turn_choices; ++t) longest_run = std::max(longest_run, turns[size_t(t)].longest_run);
  OccupancyGrid grid(strip_width, longest_run);
  std::vector<uint64_t> candidates;
  for (size_t chart : order) {
    int best_top = INT32_MAX, best_x = 0, best_y = 0, best_turns = -1;
    int64_t best_area = INT64_MAX;
    for (int turns = 0; turns < turn_choices; ++turns) {
      const BitMask& m = masks[chart][size_t(turns)];
      if (m.width > strip_width) continue;
      int y_limit = INT32_MAX;
      if (best_turns >= 0 && least_growth) {
        // Growth is at least max(width, mask width) x max(height, y + mask height).
        const int64_t least_width = std::max(result.width, m.width);
        y_limit = least_width * result.height > best_area ? -1 : int(std::min<int64_t>(INT32_MAX, best_area / least_width - m.height));
      } else if (best_turns >= 0) {
        y_limit = best_top - m.height;
      }
      const auto [x, y] = bottom_left_position(grid, m, y_limit, candidates);
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
    if (!go_on(result.width, result.height)) {
      StripResult abandoned;
      abandoned.abandoned = true;
      return abandoned;
    }
  }
  return result;
}

// Strips of fewer texels (the charts' masks with their gutters) are packed on the calling thread.
constexpr double kThreadedStripTexels = 100000;

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
  // Four turns let charts nest; with many charts two keep the cost of the search down.
  const int turn_choices = charts.size() <= 256 ? 4 : 2;
  const int max_side = std::max(settings.max_side_texels, 1);
  // Progress: the n-th packing (0-based) covers [1 - 2^-n, 1 - 2^-(n+1)] (one packing is the
  // common case: the first density fits), each packing by the charts placed in all its strips.
  ProgressSteps progress(settings.progress);
  int packings = 0;
  // One packing at `density`: the best strip, and the charts' mask sizes at that density (those of
  // the last density rasterized when this one was not).
  struct Attempt {
    StripResult best;
    bool packed = false, fits = false;
    std::vector<std::array<int, 2>> mask_size;
    bool beaten = false;  // it fits, but fills no more than settings.fill_to_beat
  };
  std::vector<std::array<int, 2>> mask_size(charts.size(), {0, 0});
  double chart_area = 0;  // 3-D-area units
  for (const ChartOutline& chart : charts)
    for (size_t i = 0; i + 2 < chart.points.size(); i += 3) {
      const Point2 &a = chart.points[i], &b = chart.points[i + 1], &c = chart.points[i + 2];
      chart_area += 0.5 * std::fabs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    }
  // Neither turn choice wins everywhere (the least growth fills small sets of charts better, the
  // lowest top some tori): both, for a few strip widths around the square.
  struct Strip {
    bool least_growth;
    double factor;
  };
  std::vector<Strip> strips;
  for (const bool least_growth : {true, false})
    for (double factor : {0.8, 0.9, 1.0, 1.15, 1.3, 1.6}) strips.push_back({least_growth, factor});
  const unsigned threads = std::clamp(std::thread::hardware_concurrency(), 1u, unsigned(strips.size()));

  // `fill_to_beat` > 0: a strip whose rectangle so far has density^2 / area at most that is given up
  // too (only the first density is packed this way; see PackingSettings::fill_to_beat).
  auto pack_at = [&](double density, double fill_to_beat) {
    const double start = 1 - std::ldexp(1.0, -packings), span = std::ldexp(1.0, -packings - 1);
    ++packings;
    // The charts' own texels alone exceed the page: not worth rasterizing (it is slow at a density
    // far too high).
    if (chart_area * density * density > double(max_side) * max_side) return Attempt{{}, false, false, mask_size, false};
    std::vector<std::array<BitMask, 4>> masks(charts.size());
    std::vector<size_t> mask_area(charts.size());
    double total_area = 0;
    int widest_needed = 1;
    for (size_t c = 0; c < charts.size(); ++c) {
      const ChartMask mask = rasterize_chart(charts[c], packed.placements[c], density, grow);
      mask_size[c] = {mask.width, mask.height};
      for (int turns = 0; turns < turn_choices; ++turns)
        masks[c][size_t(turns)] = bit_mask_of(turned(mask, turns), dilation);
      mask_area[c] = size_t(std::count(mask.texels.begin(), mask.texels.end(), uint8_t(1)));
      total_area += double(mask.width + dilation) * double(mask.height + dilation);
      widest_needed = std::max(widest_needed, std::min(mask.width, mask.height));
    }
    std::vector<size_t> order(charts.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      const int ha = std::min(mask_size[a][0], mask_size[a][1]), hb = std::min(mask_size[b][0], mask_size[b][1]);
      return mask_area[a] != mask_area[b] ? mask_area[a] > mask_area[b] : ha > hb;
    });
    // The strips packed on `threads` threads, each on its own grid (the calling thread reports
    // progress), then the smallest rectangle that fits the page kept, the first in the strips' order
    // of equals: the least (does not fit, area, longer side, strip). Every component only grows as
    // charts are placed, so a strip whose rectangle so far is already above a finished strip's is
    // given up; the one kept never is, whichever strips finish first.
    using Key = std::tuple<bool, int64_t, int, size_t>;
    auto key_of = [&](int width, int height, size_t strip) {
      return Key{std::max(width, height) > max_side, int64_t(width) * height, std::max(width, height), strip};
    };
    std::vector<StripResult> results(strips.size());
    std::atomic<size_t> next_strip{0}, placed{0};
    std::mutex finished_mutex;
    std::optional<Key> least_finished;
    std::vector<uint8_t> unwanted(strips.size(), 0);  // given up for fill_to_beat
    auto strip_width = [&](size_t s) {
      return std::max(widest_needed, int(std::ceil(std::sqrt(total_area) * strips[s].factor)));
    };
    auto work = [&](bool report) {
      for (size_t s; (s = next_strip.fetch_add(1)) < strips.size();) {
        auto go_on = [&](int packed_width, int packed_height) {
          const size_t done = placed.fetch_add(1, std::memory_order_relaxed) + 1;
          if (report) progress.at(start + span * double(done) / double(std::max<size_t>(1, strips.size() * charts.size())));
          if (fill_to_beat > 0 && density * density / (double(packed_width) * packed_height) <= fill_to_beat) {
            unwanted[s] = 1;
            return false;
          }
          const std::lock_guard lock(finished_mutex);
          return !least_finished || !(key_of(packed_width, packed_height, s) > *least_finished);
        };
        results[s] = pack_strip(masks, order, strip_width(s), dilation, turn_choices, strips[s].least_growth, go_on);
        if (results[s].position.empty()) continue;
        const std::lock_guard lock(finished_mutex);
        const Key key = key_of(results[s].width, results[s].height, s);
        if (!least_finished || key < *least_finished) least_finished = key;
      }
    };
    // Threads only for strips of some size: a small packing takes less than a helper thread's
    // start on a busy machine.
    std::vector<std::thread> helpers;
    if (total_area >= kThreadedStripTexels)
      for (unsigned t = 1; t < threads; ++t) helpers.emplace_back(work, false);
    work(true);
    for (std::thread& t : helpers) t.join();
    // A strip kept unless given up for fill_to_beat fills more than asked (or it would have been
    // given up). When none fits, whether the strips given up would have fitted decides between a
    // fitting packing that fills too little (beaten) and a smaller density: pack them in full until
    // one fits.
    bool kept_fits = false, any_unwanted = false;
    for (size_t s = 0; s < strips.size(); ++s) {
      kept_fits |= !results[s].position.empty() && std::max(results[s].width, results[s].height) <= max_side;
      any_unwanted |= unwanted[s] != 0;
    }
    if (!kept_fits && any_unwanted)
      for (size_t s = 0; s < strips.size(); ++s) {
        if (!unwanted[s]) continue;
        results[s] = pack_strip(masks, order, strip_width(s), dilation, turn_choices, strips[s].least_growth,
                                [](int, int) { return true; });
        if (!results[s].position.empty() && std::max(results[s].width, results[s].height) <= max_side) {
          Attempt beaten{{}, false, true, mask_size};
          beaten.beaten = true;
          return beaten;
        }
      }
    StripResult best;
    bool have_best = false, best_fits = false;
    for (StripResult& r : results) {
      if (r.position.empty()) continue;
      const bool fits = std::max(r.width, r.height) <= max_side;
      const double area = double(r.width) * r.height, best_area = double(best.width) * best.height;
      const bool better = !have_best || (fits && !best_fits) ||
                          (fits == best_fits &&
                           (area < best_area ||
                            (area == best_area && std::max(r.width, r.height) < std::max(best.width, best.height))));
      if (better) best = std::move(r), have_best = true, best_fits = fits;
    }
    return Attempt{std::move(best), have_best, best_fits, mask_size, false};
  };
  auto commit = [&](const Attempt& a, double density) {
    packed.fits = a.fits;
    packed.width = std::max(a.best.width, 1);
    packed.height = std::max(a.best.height, 1);
    packed.texels_per_unit = density;
    for (size_t c = 0; c < charts.size(); ++c) {
      ChartPlacement& p = packed.placements[c];
      p.mask_width = a.mask_size[c][0];
      p.mask_height = a.mask_size[c][1];
      p.quarter_turns = a.packed ? a.best.turns[c] : 0;
      p.origin = a.packed ? Point2{double(a.best.position[c][0]), double(a.best.position[c][1])} : Point2{0, 0};
    }
    progress.at(1);
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
    const double density = std::min(first, fitting);
    PackedCharts result = commit(pack_at(density, 0), density);
    result.fits = false;
    return result;
  }
  Attempt attempt = pack_at(first, settings.fill_to_beat);
  if (attempt.beaten) {
    packed.beaten = true;
    progress.at(1);
    return packed;
  }
  if (attempt.fits) return commit(attempt, first);
  // Too big for the page: shrink (at least halving) until it fits, then bisect between the two.
  double too_big = first, fitting = 0;
  Attempt fitting_attempt;
  for (int step = 0; step < 40; ++step) {
    const double next = too_big * std::min(0.5, 0.97 * double(max_side) / side_of(attempt, too_big));
    if (next * largest_extent < 0.05) break;
    attempt = pack_at(next, 0);
    if (attempt.fits) {
      fitting = next;
      fitting_attempt = std::move(attempt);
      break;
    }
    too_big = next;
  }
  if (fitting == 0) {  // nothing fitted: the smallest tried, marked as not fitting
    PackedCharts result = commit(attempt, too_big);
    result.fits = false;
    return result;
  }
  for (int step = 0; step < 6; ++step) {  // the largest fitting density within about 3 %
    const double middle = std::sqrt(fitting * too_big);
    Attempt trial = pack_at(middle, 0);
    if (trial.fits)
      fitting = middle, fitting_attempt = std::move(trial);
    else
      too_big = middle;
  }
  return commit(fitting_attempt, fitting);
}

}  // namespace exitance::uvgen
