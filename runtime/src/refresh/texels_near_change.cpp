#include "exitance/runtime/refresh/texels_near_change.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <thread>
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
                                         const TexelGrid* grid) {
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
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> rows(boxes.size());
    size_t entries = 0;
    for (size_t b = 0; b < boxes.size(); ++b) entries += grid->candidate_rows(boxes[b], std::sqrt(radius_squared[b]), rows[b]);
    auto near_box = [&](size_t b, uint32_t i) { return boxes[b].distance_squared(edited.gbuffer.texels[i].position) <= radius_squared[b]; };
    if (entries < n / 32) {
      // A short list (a light's room): in order and each once by a sort (boxes overlap).
      for (size_t b = 0; b < boxes.size(); ++b) {
        for (const auto& [begin, end] : rows[b])
          for (uint32_t k = begin; k < end; ++k)
            if (boxes[b].distance_squared(grid->entry_position(k)) <= radius_squared[b]) {
              const uint32_t i = grid->entry(k);
              if (!grid->is_displaced(i)) near.push_back(i);
            }
        for (uint32_t i : grid->displaced())
          if (near_box(b, i)) near.push_back(i);
      }
      std::sort(near.begin(), near.end());
      near.erase(std::unique(near.begin(), near.end()), near.end());
      return near;
    }
    // A long one (hundreds of thousands of texels near a moved block): a mark per texel, the rows
    // on all cores (a row lists a texel once, so one box's rows write distinct marks), then the
    // marks read back in order, also on all cores.
    std::vector<uint8_t> is_near(n, 0);
    for (size_t b = 0; b < boxes.size(); ++b) {
      const auto& box_rows = rows[b];
      for_each_chunk(box_rows.size(), [&](size_t first, size_t last) {
        for (size_t r = first; r < last; ++r)
          for (uint32_t k = box_rows[r].first; k < box_rows[r].second; ++k)
            if (boxes[b].distance_squared(grid->entry_position(k)) <= radius_squared[b]) {
              const uint32_t i = grid->entry(k);
              if (!grid->is_displaced(i)) is_near[i] = 1;
            }
      }, 64);
      for (uint32_t i : grid->displaced())
        if (near_box(b, i)) is_near[i] = 1;
    }
    // Read back 8 marks at a time: the near texels cluster, most words are zero.
    near.reserve(std::min(entries, n));
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
      uint64_t word;
      std::memcpy(&word, &is_near[i], 8);
      if (word == 0) continue;
      for (size_t j = i; j < i + 8; ++j)
        if (is_near[j]) near.push_back(uint32_t(j));
    }
    for (; i < n; ++i)
      if (is_near[i]) near.push_back(uint32_t(i));
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
