#include "exitance/runtime/refresh/texels_near_change.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <utility>

#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

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
  std::vector<float> radius_squared;
  for (const WorldBox& b : boxes) {
    const float r = std::max(2.0f * b.half_diagonal(), 0.1f * edited_lighting.extent);
    radius_squared.push_back(r * r);
  }
  std::vector<uint32_t> near;
  const size_t n = edited.gbuffer.texels.size();
  if (grid && grid->texel_count() == n) {
    // A mark per texel (the caller's zeroed scratch when given: an edit allocates and zeroes no
    // megabyte), the rows of cells on all cores (a row lists a texel once, so one box's rows write
    // distinct marks; boxes in turn), then the marks between the lowest and highest marked texel
    // read back in order 8 at a time (the near texels cluster), and left zero again.
    std::vector<uint8_t> own;
    std::vector<uint8_t>& is_near = marks && marks->size() == n ? *marks : own;
    if (&is_near == &own) own.assign(n, 0);
    std::atomic<uint32_t> lowest{UINT32_MAX}, highest{0};
    auto mark = [&](uint32_t i, uint32_t& lo, uint32_t& hi) { is_near[i] = 1, lo = std::min(lo, i), hi = std::max(hi, i); };
    auto keep_range = [&](uint32_t lo, uint32_t hi) {
      for (uint32_t v = lowest.load(); lo < v && !lowest.compare_exchange_weak(v, lo);) {}
      for (uint32_t v = highest.load(); hi > v && !highest.compare_exchange_weak(v, hi);) {}
    };
    std::vector<std::pair<uint32_t, uint32_t>> rows;
    for (size_t b = 0; b < boxes.size(); ++b) {
      grid->candidate_rows(boxes[b], std::sqrt(radius_squared[b]), rows);
      for_each_chunk(rows.size(), [&](size_t first, size_t last) {
        uint32_t lo = UINT32_MAX, hi = 0;
        for (size_t r = first; r < last; ++r)
          for (uint32_t k = rows[r].first; k < rows[r].second; ++k)
            if (boxes[b].distance_squared(grid->entry_position(k)) <= radius_squared[b])
              if (const uint32_t i = grid->entry(k); !grid->is_displaced(i)) mark(i, lo, hi);
        keep_range(lo, hi);
      }, 256);
      uint32_t lo = UINT32_MAX, hi = 0;
      for (uint32_t i : grid->displaced())
        if (boxes[b].distance_squared(edited.gbuffer.texels[i].position) <= radius_squared[b]) mark(i, lo, hi);
      keep_range(lo, hi);
    }
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
    for (size_t b = 0; b < boxes.size(); ++b)
      if (boxes[b].distance_squared(p) <= radius_squared[b]) {
        near.push_back(uint32_t(i));
        break;
      }
  }
  return near;
}

}  // namespace exitance
