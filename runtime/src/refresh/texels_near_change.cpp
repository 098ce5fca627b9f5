#include "exitance/runtime/refresh/texels_near_change.h"

#include <algorithm>
#include <cmath>

namespace exitance {
namespace {

struct Box {
  Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  void add(const Vec3& p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  float half_diagonal() const { return lo.x <= hi.x ? 0.5f * length(hi - lo) : 0.0f; }
  float distance_squared(const Vec3& p) const {
    const float dx = std::max({lo.x - p.x, 0.0f, p.x - hi.x});
    const float dy = std::max({lo.y - p.y, 0.0f, p.y - hi.y});
    const float dz = std::max({lo.z - p.z, 0.0f, p.z - hi.z});
    return dx * dx + dy * dy + dz * dz;
  }
};

Box triangles_box(const Scene& scene, uint32_t first, uint32_t count) {
  Box box;
  for (size_t v = size_t(first) * 3; v < size_t(first + count) * 3; ++v) box.add(scene.positions[v]);
  return box;
}

}  // namespace

std::vector<uint32_t> texels_near_change(const PersistedScene& edited, const Scene& before,
                                         const LightingScene& edited_lighting, const EditEffects& effects) {
  if (effects.sky) return {};  // the sky lights everything
  std::vector<Box> boxes;
  for (uint32_t k : effects.moved_instances) {
    boxes.push_back(triangles_box(before, before.instances[k].first_triangle, before.instances[k].triangle_count));
    const Instance& moved = edited.scene.instances[k];
    boxes.push_back(triangles_box(edited.scene, moved.first_triangle, moved.triangle_count));
  }
  for (uint32_t l : effects.lights) {
    const PunctualLight& light = edited.scene.lights[l];
    if (light.type == PunctualLight::Type::Directional) return {};  // it lights everything it reaches
    Box box;
    box.add(light.position);
    if (l < before.lights.size()) box.add(before.lights[l].position);
    boxes.push_back(box);
  }
  if (!effects.materials.empty()) {
    std::vector<uint8_t> edited_material(edited.scene.materials.size(), 0);
    for (uint32_t m : effects.materials) edited_material[m] = 1;
    Box box;
    for (size_t t = 0; t < edited.scene.triangle_count(); ++t)
      if (edited_material[edited.scene.triangle_material[t]]) {
        const Vec3* p = &edited.scene.positions[t * 3];
        box.add(p[0]), box.add(p[1]), box.add(p[2]);
      }
    if (box.lo.x <= box.hi.x) boxes.push_back(box);
  }
  if (boxes.empty()) return {};
  // Near: within twice a changed box's half-diagonal of it (there the box still spans about 30
  // degrees or more of a texel's view, so its light, shadow or occlusion weighs), at least a tenth
  // of the scene's extent (a light's box is a point).
  std::vector<float> radius_squared;
  for (const Box& b : boxes) {
    const float r = std::max(2.0f * b.half_diagonal(), 0.1f * edited_lighting.extent);
    radius_squared.push_back(r * r);
  }
  std::vector<uint32_t> near;
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
