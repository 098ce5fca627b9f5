#include "exitance/runtime/refresh/unocclude_near_moved.h"

#include <algorithm>
#include <vector>

#include "exitance/runtime/core/bvh4_closest_hit.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/texel_surface.h"
#include "exitance/runtime/unocclude_texel.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

std::vector<uint32_t> unocclude_near_boxes(PersistedScene& edited, const std::vector<WorldBox>& boxes,
                                           const LightingScene& edited_lighting, const TexelGrid* grid) {
  std::vector<uint32_t> reconsidered;
  if (boxes.empty()) return reconsidered;
  const ClosestHitQuery query = [&](const Vec3& origin, const Vec3& direction, float t_max) {
    const BvhHit hit = closest_hit(edited_lighting, origin, direction, t_max);
    return OccluderHit{hit.found, hit.distance, hit.geometric_normal};
  };
  // Whether texel i lies within reach of a box, and then its unocclude step again (each texel reads
  // only itself and the BVH: chunks of texels run on threads).
  auto reconsider = [&](uint32_t i) {
    LiveTexel& texel = edited.gbuffer.texels[i];
    // A pushed texel lies at most its reach from its surface point: test the current position
    // against the bounds grown by twice the reach, then the surface point by the reach.
    const float reach = texel.world_texel_size * 0.75f;
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const WorldBox& b) { return b.contains(texel.position, 2 * reach); })) return false;
    const AtlasPage& page = edited.gbuffer.pages[texel.page];
    float b1, b2;
    texel_barycentrics(edited.scene, edited.atlas.rects[texel.instance], page.width, page.height, texel.triangle,
                       texel.x, texel.y, b1, b2);
    const Vec3 surface = texel_surface(edited.scene, texel.triangle, b1, b2).position;
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const WorldBox& b) { return b.contains(surface, reach); })) return false;
    texel.position = surface;
    unocclude_texel(texel, edited_lighting.extent, query);
    return true;
  };
  auto reconsider_all = [&](const std::vector<uint32_t>& texels) {
    std::vector<uint8_t> done(texels.size(), 0);
    for_each_chunk(texels.size(), [&](size_t begin, size_t end) {
      for (size_t k = begin; k < end; ++k) done[k] = reconsider(texels[k]) ? 1 : 0;
    }, 512);
    for (size_t k = 0; k < texels.size(); ++k)
      if (done[k]) reconsidered.push_back(texels[k]);
  };
  if (grid && grid->texel_count() == edited.gbuffer.texels.size()) {
    // Candidates within twice the largest reach of a box, each once, ascending.
    std::vector<uint32_t> candidates;
    const float margin = 2 * 0.75f * grid->largest_texel_size();
    for (const WorldBox& b : boxes) grid->for_each_candidate(b, margin, [&](uint32_t i) { candidates.push_back(i); });
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    reconsider_all(candidates);
  } else {
    std::vector<uint32_t> all(edited.gbuffer.texels.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
    reconsider_all(all);
  }
  return reconsidered;
}

}  // namespace exitance
