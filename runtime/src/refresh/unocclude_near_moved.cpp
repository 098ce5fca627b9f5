#include "exitance/runtime/refresh/unocclude_near_moved.h"

#include <algorithm>
#include <vector>

#include "exitance/runtime/core/bvh4_closest_hit.h"
#include "exitance/runtime/texel_surface.h"
#include "exitance/runtime/unocclude_texel.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

size_t unocclude_near_moved(PersistedScene& edited, const Scene& before, const LightingScene& edited_lighting,
                            const EditEffects& effects) {
  if (effects.moved_instances.empty()) return 0;
  std::vector<WorldBox> boxes;
  for (uint32_t k : effects.moved_instances) {
    boxes.push_back(instance_world_box(before, before.instances[k]));
    boxes.push_back(instance_world_box(edited.scene, edited.scene.instances[k]));
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
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const WorldBox& b) { return b.contains(texel.position, 2 * reach); })) continue;
    const AtlasPage& page = edited.gbuffer.pages[texel.page];
    float b1, b2;
    texel_barycentrics(edited.scene, edited.atlas.rects[texel.instance], page.width, page.height, texel.triangle,
                       texel.x, texel.y, b1, b2);
    const Vec3 surface = texel_surface(edited.scene, texel.triangle, b1, b2).position;
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const WorldBox& b) { return b.contains(surface, reach); })) continue;
    texel.position = surface;
    unocclude_texel(texel, edited_lighting.extent, query);
    ++reconsidered;
  }
  return reconsidered;
}

}  // namespace exitance
