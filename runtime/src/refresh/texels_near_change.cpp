#include "exitance/runtime/refresh/texels_near_change.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <utility>

#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/world_box.h"

namespace exitance {
namespace {

// Where texels count as near a change: within `radius_squared` of `box`, or (toward_light set) on a
// ray toward a directional light that passes through `box` (its shadow); `candidates` bounds both.
struct Region {
  WorldBox box, candidates;
  float radius_squared = 0;
  Vec3 toward_light{0, 0, 0};
  bool holds(const Vec3& p) const {
    if (!candidates.contains(p, 0.0f)) return false;
    if (toward_light.x == 0 && toward_light.y == 0 && toward_light.z == 0) return box.distance_squared(p) <= radius_squared;
    // Slab test of the ray p + t toward_light, t >= 0.
    float t0 = 0, t1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
      if (std::fabs(toward_light[a]) < 1e-12f) {
        if (p[a] < box.lo[a] || p[a] > box.hi[a]) return false;
        continue;
      }
      const float inverse = 1.0f / toward_light[a];
      float near_t = (box.lo[a] - p[a]) * inverse, far_t = (box.hi[a] - p[a]) * inverse;
      if (near_t > far_t) std::swap(near_t, far_t);
      t0 = std::max(t0, near_t), t1 = std::min(t1, far_t);
      if (t0 > t1) return false;
    }
    return true;
  }
};

}  // namespace

std::vector<uint32_t> texels_near_change(const PersistedScene& edited, const Scene& before,
                                         const LightingScene& edited_lighting, const EditEffects& effects,
                                         const TexelGrid* grid) {
  ChangeBefore was;
  for (const PunctualLight& light : before.lights) was.light_positions.push_back(light.position);
  for (uint32_t k : effects.moved_instances) {
    was.moved_boxes_before.push_back(instance_world_box(before, before.instances[k]));
    was.moved_boxes_after.push_back(instance_world_box(edited.scene, edited.scene.instances[k]));
  }
  return texels_near_change(edited, was, edited_lighting, effects, grid);
}

std::vector<uint32_t> texels_near_change(const PersistedScene& edited, const ChangeBefore& was,
                                         const LightingScene& edited_lighting, const EditEffects& effects,
                                         const TexelGrid* grid, std::vector<uint8_t>* marks) {
  if (effects.sky) return {};  // the sky lights everything
  std::vector<WorldBox> boxes;
  for (size_t j = 0; j < effects.moved_instances.size() && j < was.moved_boxes_before.size() && j < was.moved_boxes_after.size(); ++j) {
    boxes.push_back(was.moved_boxes_before[j]);
    boxes.push_back(was.moved_boxes_after[j]);
  }
  for (uint32_t l : effects.lights) {
    const PunctualLight& light = edited.scene.lights[l];
    if (light.type == PunctualLight::Type::Directional) return {};  // it lights everything it reaches
    WorldBox box;
    box.grow(light.position);
    if (l < was.light_positions.size()) box.grow(was.light_positions[l]);
    boxes.push_back(box);
  }
  if (!effects.materials.empty()) {
    std::vector<uint8_t> edited_material(edited.scene.materials.size(), 0);
    for (uint32_t m : effects.materials) edited_material[m] = 1;
    WorldBox box;
    for (size_t t = 0; t < edited.scene.triangle_count(); ++t)
      if (edited_material[edited.scene.triangle_material[t]]) {
        const Vec3* p = &edited.scene.positions[t * 3];
        box.grow(p[0]), box.grow(p[1]), box.grow(p[2]);
      }
    if (!box.empty()) boxes.push_back(box);
  }
  if (boxes.empty()) return {};
  // Near: within twice a changed box's half-diagonal of it (there the box still spans about 30
  // degrees or more of a texel's view, so its light, shadow or occlusion weighs), at least a tenth
  // of the scene's extent (a light's box is a point).
  std::vector<Region> regions;
  for (const WorldBox& b : boxes) {
    const float r = std::max(2.0f * b.half_diagonal(), 0.1f * edited_lighting.extent);
    Region region;
    region.box = b;
    region.radius_squared = r * r;
    region.candidates = b;
    region.candidates.lo = region.candidates.lo - Vec3{r, r, r};
    region.candidates.hi = region.candidates.hi + Vec3{r, r, r};
    regions.push_back(region);
  }
  // And where a moved instance casts or cast a directional light's shadow (seed 003's rule: texels
  // whose path to a light passes through the old or new bounds): a low sun's shadow reaches beyond
  // the near radius. The shadow runs from the box along the light until it leaves the scene's
  // bounds; its candidates are the cells of 8 boxes along that sweep (one box around the diagonal
  // sweep would hold most of the scene), and none when the near radius already holds it all.
  WorldBox scene_bounds;
  scene_bounds.grow(edited_lighting.bounds_lo), scene_bounds.grow(edited_lighting.bounds_hi);
  const size_t moved_boxes = std::min(2 * effects.moved_instances.size(), boxes.size());
  for (size_t j = 0; j < moved_boxes && !scene_bounds.empty(); ++j)
    for (const PunctualLight& light : edited.scene.lights) {
      if (light.type != PunctualLight::Type::Directional || !(max_component(light.intensity) > 0)) continue;
      const Vec3 travel = normalize(light.direction);
      if (!is_finite(travel)) continue;
      const WorldBox& box = boxes[j];
      float reach = 0;  // how far along `travel` the box's corners stay inside the scene's bounds
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner{c & 1 ? box.hi.x : box.lo.x, c & 2 ? box.hi.y : box.lo.y, c & 4 ? box.hi.z : box.lo.z};
        float exit = INFINITY;
        for (int a = 0; a < 3; ++a)
          if (std::fabs(travel[a]) > 1e-12f) exit = std::min(exit, ((travel[a] > 0 ? scene_bounds.hi[a] : scene_bounds.lo[a]) - corner[a]) / travel[a]);
        reach = std::max(reach, std::min(exit, 2.0f * scene_bounds.half_diagonal()));
      }
      if (!(reach > 0) || reach * reach <= regions[j].radius_squared) continue;
      constexpr int kPieces = 8;
      for (int k = 0; k < kPieces; ++k) {
        Region shadow;
        shadow.box = box;
        shadow.toward_light = travel * -1.0f;
        const float from = reach * float(k) / kPieces, to = reach * float(k + 1) / kPieces;
        shadow.candidates = WorldBox{box.lo + travel * from, box.hi + travel * from};
        shadow.candidates.grow(WorldBox{box.lo + travel * to, box.hi + travel * to});
        shadow.candidates.lo = max(shadow.candidates.lo, scene_bounds.lo);
        shadow.candidates.hi = min(shadow.candidates.hi, scene_bounds.hi);
        if (!shadow.candidates.empty()) regions.push_back(shadow);
      }
    }
  std::vector<uint32_t> near;
  const size_t n = edited.gbuffer.texels.size();
  if (grid && grid->texel_count() == n) {
    // A mark per texel (the caller's zeroed scratch when given: an edit allocates and zeroes no
    // megabyte), the rows of cells on all cores, then the marks between the lowest and highest
    // marked texel read back in order 8 at a time (the near texels cluster), and left zero again.
    std::vector<uint8_t> own;
    std::vector<uint8_t>& is_near = marks && marks->size() == n ? *marks : own;
    if (&is_near == &own) own.assign(n, 0);
    std::atomic<uint32_t> lowest{UINT32_MAX}, highest{0};
    auto mark = [&](uint32_t i, uint32_t& lo, uint32_t& hi) {
      std::atomic_ref<uint8_t>(is_near[i]).store(1, std::memory_order_relaxed);
      lo = std::min(lo, i), hi = std::max(hi, i);
    };
    auto keep_range = [&](uint32_t lo, uint32_t hi) {
      for (uint32_t v = lowest.load(); lo < v && !lowest.compare_exchange_weak(v, lo);) {}
      for (uint32_t v = highest.load(); hi > v && !highest.compare_exchange_weak(v, hi);) {}
    };
    // Every region's rows in one pass on all cores (regions overlap: a mark is stored atomically).
    struct Row {
      uint32_t region, first, end;
    };
    std::vector<Row> rows;
    std::vector<std::pair<uint32_t, uint32_t>> region_rows;
    for (size_t r = 0; r < regions.size(); ++r) {
      grid->candidate_rows(regions[r].candidates, 0.0f, region_rows);
      for (const auto& [first, end] : region_rows) rows.push_back({uint32_t(r), first, end});
    }
    for_each_chunk(rows.size(), [&](size_t first, size_t last) {
      uint32_t lo = UINT32_MAX, hi = 0;
      for (size_t r = first; r < last; ++r) {
        const Region& region = regions[rows[r].region];
        for (uint32_t k = rows[r].first; k < rows[r].end; ++k)
          if (region.holds(grid->entry_position(k)))
            if (const uint32_t i = grid->entry(k); !grid->is_displaced(i)) mark(i, lo, hi);
      }
      keep_range(lo, hi);
    }, 4);
    const std::vector<uint32_t>& displaced = grid->displaced();  // up to an eighth of the texels
    for_each_chunk(displaced.size(), [&](size_t first, size_t last) {
      uint32_t lo = UINT32_MAX, hi = 0;
      for (size_t k = first; k < last; ++k) {
        const uint32_t i = displaced[k];
        if (std::any_of(regions.begin(), regions.end(), [&](const Region& region) { return region.holds(edited.gbuffer.texels[i].position); }))
          mark(i, lo, hi);
      }
      keep_range(lo, hi);
    }, 16384);
    if (lowest.load() > highest.load()) return near;
    size_t i = lowest.load();
    const size_t stop = size_t(highest.load()) + 1;
    for (; i + 8 <= stop; i += 8) {
      uint64_t word;
      std::memcpy(&word, &is_near[i], 8);
      if (word == 0) continue;
      for (size_t j = i; j < i + 8; ++j)
        if (is_near[j]) near.push_back(uint32_t(j)), is_near[j] = 0;
    }
    for (; i < stop; ++i)
      if (is_near[i]) near.push_back(uint32_t(i)), is_near[i] = 0;
    return near;
  }
  for (size_t i = 0; i < edited.gbuffer.texels.size(); ++i) {
    const Vec3& p = edited.gbuffer.texels[i].position;
    if (std::any_of(regions.begin(), regions.end(), [&](const Region& region) { return region.holds(p); })) near.push_back(uint32_t(i));
  }
  return near;
}

}  // namespace exitance
