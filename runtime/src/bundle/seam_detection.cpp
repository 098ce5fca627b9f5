#include "exitance/runtime/bundle/seam_detection.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <thread>

#include "exitance/runtime/texel_surface.h"

namespace exitance {
namespace {

// Welds corners by position: a grid of cells one tolerance wide, each corner joined to an earlier
// point within the tolerance in its own or a neighbouring cell. Cells are found by a 64-bit hash of
// their coordinates (cells whose hashes collide share a list, as they would share a map entry); each
// cell lists its points in the order they were added, so the first match is the same whatever the
// table's layout. An open-addressing table with the lists threaded through the points (27 lookups
// per corner: a node-based map spent most of seam detection there).
class PositionWeld {
 public:
  explicit PositionWeld(float tolerance, size_t expected_points = 0) : tolerance_(tolerance) {
    size_t capacity = 64;
    while (capacity < 2 * expected_points) capacity *= 2;
    slots_.assign(capacity, Slot{});
  }

  uint32_t id(Vec3 p) {
    const std::array<int64_t, 3> cell = cell_of(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const Slot* found = find(key({cell[0] + dx, cell[1] + dy, cell[2] + dz}));
          if (!found) continue;
          for (uint32_t candidate = found->first; candidate != kNone; candidate = next_[candidate])
            if (length(points_[candidate] - p) <= tolerance_) return candidate;
        }
    const uint32_t added = uint32_t(points_.size());
    points_.push_back(p);
    next_.push_back(kNone);
    Slot& slot = insert(key(cell));
    if (slot.first == kNone) slot.first = added;
    else next_[slot.last] = added;
    slot.last = added;
    return added;
  }

 private:
  static constexpr uint32_t kNone = ~0u;
  struct Slot {
    uint64_t key = 0;
    uint32_t first = kNone, last = kNone;  // first == kNone: empty
  };

  std::array<int64_t, 3> cell_of(Vec3 p) const {
    return {int64_t(std::floor(p.x / tolerance_)), int64_t(std::floor(p.y / tolerance_)),
            int64_t(std::floor(p.z / tolerance_))};
  }
  static uint64_t key(const std::array<int64_t, 3>& c) {
    return (uint64_t(c[0]) * 73856093u) ^ (uint64_t(c[1]) * 19349663u) ^ (uint64_t(c[2]) * 83492791u);
  }
  size_t home(uint64_t k) const { return size_t((k * 0x9E3779B97F4A7C15ull) >> 20) & (slots_.size() - 1); }

  const Slot* find(uint64_t k) const {
    for (size_t i = home(k);; i = (i + 1) & (slots_.size() - 1)) {
      const Slot& slot = slots_[i];
      if (slot.first == kNone) return nullptr;
      if (slot.key == k) return &slot;
    }
  }
  Slot& insert(uint64_t k) {
    if (2 * (used_ + 1) > slots_.size()) grow();
    for (size_t i = home(k);; i = (i + 1) & (slots_.size() - 1)) {
      Slot& slot = slots_[i];
      if (slot.first == kNone) {
        slot.key = k;
        ++used_;
        return slot;
      }
      if (slot.key == k) return slot;
    }
  }
  void grow() {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(old.size() * 2, Slot{});
    for (const Slot& slot : old) {
      if (slot.first == kNone) continue;
      size_t i = home(slot.key);
      while (slots_[i].first != kNone) i = (i + 1) & (slots_.size() - 1);
      slots_[i] = slot;
    }
  }

  float tolerance_;
  std::vector<Vec3> points_;
  std::vector<uint32_t> next_;  // the next point of the same cell list, in the order added
  std::vector<Slot> slots_;
  size_t used_ = 0;
};

// One triangle's edge from corner `from` to corner `to` (indices into the scene's corner arrays).
struct HalfEdge {
  size_t from, to;
};

bool normals_agree(Vec3 a, Vec3 b, float min_cosine) { return dot(a, b) >= min_cosine * length(a) * length(b); }

float distance(Vec2 a, Vec2 b) { return std::hypot(a.x - b.x, a.y - b.y); }

// The seams of instance i (its own welded positions and chart texels), in the order of their keys.
std::vector<SeamEdge> instance_seams(const Scene& scene, const AtlasLayout& layout, const SeamDetectionSettings& settings,
                                     size_t i) {
  const float min_cosine = std::cos(settings.max_normal_angle_degrees * 3.14159265358979f / 180.0f);
  std::vector<SeamEdge> seams;
  const Instance& instance = scene.instances[i];
  const InstanceRect& rect = layout.rects[i];
  if (instance.triangle_count == 0 || size_t(rect.page) >= layout.page_sizes.size()) return seams;
  const auto [page_width, page_height] = layout.page_sizes[size_t(rect.page)];
  const size_t first_corner = size_t(instance.first_triangle) * 3;
  const size_t end_corner = first_corner + size_t(instance.triangle_count) * 3;
  Vec3 lo = scene.positions[first_corner], hi = lo;
  for (size_t c = first_corner; c < end_corner; ++c) lo = min(lo, scene.positions[c]), hi = max(hi, scene.positions[c]);
  const float diagonal = length(hi - lo);
  if (!(diagonal > 0)) return seams;
  PositionWeld weld(settings.weld_tolerance * diagonal, end_corner - first_corner);
  std::vector<uint32_t> welded(end_corner - first_corner);
  for (size_t c = first_corner; c < end_corner; ++c) welded[c - first_corner] = weld.id(scene.positions[c]);
  std::vector<Vec2> texel(end_corner - first_corner);
  for (uint32_t t = instance.first_triangle; t < instance.first_triangle + instance.triangle_count; ++t) {
    Vec2 tri[3];
    chart_triangle_in_texels(scene, t, rect.scale_offset, page_width, page_height, tri);
    for (int k = 0; k < 3; ++k) texel[size_t(t) * 3 + size_t(k) - first_corner] = tri[k];
  }
  // Half-edges keyed by their undirected welded edge, sorted by (key, corner): the edges come out
  // in key order, each edge's half-edges in corner order, as deterministic as an ordered map of
  // lists and several times faster (no node per edge).
  struct KeyedHalfEdge {
    uint64_t key;
    HalfEdge edge;
  };
  std::vector<KeyedHalfEdge> keyed;
  keyed.reserve(end_corner - first_corner);
  for (size_t t = instance.first_triangle; t < size_t(instance.first_triangle) + instance.triangle_count; ++t)
    for (size_t k = 0; k < 3; ++k) {
      const size_t from = t * 3 + k, to = t * 3 + (k + 1) % 3;
      const uint32_t a = welded[from - first_corner], b = welded[to - first_corner];
      if (a == b) continue;  // degenerate edge
      keyed.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), {from, to}});
    }
  std::sort(keyed.begin(), keyed.end(), [](const KeyedHalfEdge& x, const KeyedHalfEdge& y) {
    return x.key != y.key ? x.key < y.key : x.edge.from < y.edge.from;
  });
  for (size_t begin = 0, end = 0; begin < keyed.size(); begin = end) {
    end = begin;
    while (end < keyed.size() && keyed[end].key == keyed[begin].key) ++end;
    if (end - begin != 2) continue;  // a border, or non-manifold
    const HalfEdge e0 = keyed[begin].edge;
    // The second half-edge's corners in the order of the first's 3-D endpoints.
    HalfEdge e1 = keyed[begin + 1].edge;
    if (welded[e1.from - first_corner] != welded[e0.from - first_corner]) std::swap(e1.from, e1.to);
    const Vec2 a0 = texel[e0.from - first_corner], a1 = texel[e0.to - first_corner];
    const Vec2 b0 = texel[e1.from - first_corner], b1 = texel[e1.to - first_corner];
    const float tol = settings.same_uv_tolerance_texels;
    if (distance(a0, b0) <= tol && distance(a1, b1) <= tol) continue;  // one edge in the atlas too
    if (!(distance(a0, a1) > tol) || !(distance(b0, b1) > tol)) continue;  // collapsed in UV
    if (!normals_agree(scene.normals[e0.from], scene.normals[e1.from], min_cosine) ||
        !normals_agree(scene.normals[e0.to], scene.normals[e1.to], min_cosine))
      continue;  // a hard edge
    SeamEdge seam;
    seam.instance = uint32_t(i);
    seam.page = rect.page;
    seam.side_a[0] = a0, seam.side_a[1] = a1;
    seam.side_b[0] = b0, seam.side_b[1] = b1;
    seams.push_back(seam);
  }
  return seams;
}

}  // namespace

// Instances are independent: worker threads take them in turn, and the seams are concatenated in
// instance order, so the result does not depend on the thread count (a scene of many instances,
// such as the open city, spent a second here on one core).
std::vector<SeamEdge> find_lightmap_seams(const Scene& scene, const AtlasLayout& layout,
                                          const SeamDetectionSettings& settings) {
  const size_t count = std::min(scene.instances.size(), layout.rects.size());
  std::vector<std::vector<SeamEdge>> per_instance(count);
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i = next++; i < count; i = next++) per_instance[i] = instance_seams(scene, layout, settings, i);
  };
  const size_t threads = std::min<size_t>(std::max(1u, std::thread::hardware_concurrency()), count);
  std::vector<std::thread> workers;
  for (size_t t = 1; t < threads; ++t) workers.emplace_back(work);
  work();
  for (std::thread& w : workers) w.join();
  std::vector<SeamEdge> seams;
  for (std::vector<SeamEdge>& part : per_instance) seams.insert(seams.end(), part.begin(), part.end());
  return seams;
}

}  // namespace exitance
