#include "exitance/runtime/refresh/unocclude_near_moved.h"

#include <algorithm>
#include <vector>

#include "exitance/runtime/core/bvh4_closest_hit.h"
#include "exitance/runtime/texel_surface.h"
#include "exitance/runtime/unocclude_texel.h"

namespace exitance {
namespace {

struct Box {
  Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  void add(const Vec3& p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  bool near(const Vec3& p, float margin) const {
    return p.x >= lo.x - margin && p.x <= hi.x + margin && p.y >= lo.y - margin && p.y <= hi.y + margin &&
           p.z >= lo.z - margin && p.z <= hi.z + margin;
  }
};

Box instance_bounds(const Scene& scene, const Instance& instance) {
  Box box;
  for (size_t v = size_t(instance.first_triangle) * 3; v < size_t(instance.first_triangle + instance.triangle_count) * 3; ++v)
    box.add(scene.positions[v]);
  return box;
}

}  // namespace

size_t unocclude_near_moved(PersistedScene& edited, const Scene& before, const LightingScene& edited_lighting,
                            const EditEffects& effects) {
  if (effects.moved_instances.empty()) return 0;
  std::vector<Box> boxes;
  for (uint32_t k : effects.moved_instances) {
    boxes.push_back(instance_bounds(before, before.instances[k]));
    boxes.push_back(instance_bounds(edited.scene, edited.scene.instances[k]));
  }
  const ClosestHitQuery query = [&](const Vec3& origin, const Vec3& direction, float t_max) {
    const BvhHit hit = closest_hit(edited_lighting, origin, direction, t_max);
    return OccluderHit{hit.found, hit.distance, hit.geometric_normal};
  };
  size_t reconsidered = 0;
  for (LiveTexel& texel : edited.gbuffer.texels) {
    // A pushed texel lies at most its reach from its surface point: test the current position
    // against the bounds grown by twice the reach, then the surface point by the reach.
    const float reach = texel.world_texel_size * 0.75f;
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const Box& b) { return b.near(texel.position, 2 * reach); })) continue;
    const AtlasPage& page = edited.gbuffer.pages[texel.page];
    float b1, b2;
    texel_barycentrics(edited.scene, edited.atlas.rects[texel.instance], page.width, page.height, texel.triangle,
                       texel.x, texel.y, b1, b2);
    const Vec3 surface = texel_surface(edited.scene, texel.triangle, b1, b2).position;
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const Box& b) { return b.near(surface, reach); })) continue;
    texel.position = surface;
    unocclude_texel(texel, edited_lighting.extent, query);
    ++reconsidered;
  }
  return reconsidered;
}

}  // namespace exitance
