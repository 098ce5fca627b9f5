#include "exitance/runtime/refresh/unocclude_near_moved.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "exitance/runtime/core/bvh4_closest_hit.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/node_transform.h"
#include "exitance/runtime/texel_surface.h"
#include "exitance/runtime/unocclude_texel.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

std::vector<uint32_t> unocclude_near_boxes(PersistedScene& edited, const std::vector<WorldBox>& boxes,
                                           const LightingScene& edited_lighting, const TexelGrid* grid,
                                           const std::vector<uint32_t>* carried) {
  std::vector<uint32_t> reconsidered;
  if (boxes.empty()) return reconsidered;
  const ClosestHitQuery query = [&](const Vec3& origin, const Vec3& direction, float t_max) {
    const BvhHit hit = closest_hit(edited_lighting, origin, direction, t_max);
    return OccluderHit{hit.found, hit.distance, hit.geometric_normal};
  };
  // Whether texel i lies within reach of a box (cheap tests; then placed on its surface point).
  auto within_reach = [&](uint32_t i) {
    if (carried && std::binary_search(carried->begin(), carried->end(), i)) return false;
    LiveTexel& texel = edited.gbuffer.texels[i];
    // A pushed texel lies at most its reach from its surface point: test the current position
    // against the bounds grown by twice the reach, then the surface point by the reach.
    const float reach = texel.world_texel_size * 0.75f;
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const WorldBox& b) { return b.contains(texel.position, 2 * reach); })) return false;
    const AtlasPage& page = edited.gbuffer.pages[texel.page];
    float b1, b2;
    texel_barycentrics(edited.scene, edited.atlas.rects[texel.instance], page.width, page.height, texel.triangle,
                       texel.x, texel.y, b1, b2);
    const Vec3 surface = texel_surface_position(edited.scene, texel.triangle, b1, b2);
    if (!std::any_of(boxes.begin(), boxes.end(), [&](const WorldBox& b) { return b.contains(surface, reach); })) return false;
    texel.position = surface;
    return true;
  };
  // The tests first over all candidates, then the unocclude step (8 rays each) over those within
  // reach in small chunks: those cluster in index order (a block's own texels not carried), so
  // contiguous chunks of all candidates could leave most of the rays to a few threads.
  auto reconsider_all = [&](const std::vector<uint32_t>& texels) {
    std::vector<uint8_t> within(texels.size(), 0);
    for_each_chunk(texels.size(), [&](size_t begin, size_t end) {
      for (size_t k = begin; k < end; ++k) within[k] = within_reach(texels[k]) ? 1 : 0;
    }, 256);
    for (size_t k = 0; k < texels.size(); ++k)
      if (within[k]) reconsidered.push_back(texels[k]);
    for_each_chunk(reconsidered.size(), [&](size_t begin, size_t end) {
      for (size_t k = begin; k < end; ++k) unocclude_texel(edited.gbuffer.texels[reconsidered[k]], edited_lighting.extent, query);
    }, 16);
  };
  if (grid && grid->texel_count() == edited.gbuffer.texels.size()) {
    // Candidates within twice the largest reach of a box, each once, ascending: the cells' texels
    // tested by the positions the grid keeps in cell order (a block's cells hold ~100 000 texels,
    // a few thousand of them within reach), the displaced ones by their own.
    std::vector<uint32_t> candidates;
    const float margin = 2 * 0.75f * grid->largest_texel_size();
    auto within = [&](const Vec3& p) { return std::any_of(boxes.begin(), boxes.end(), [&](const WorldBox& b) { return b.contains(p, margin); }); };
    std::vector<std::pair<uint32_t, uint32_t>> rows, box_rows;
    for (const WorldBox& b : boxes) {
      grid->candidate_rows(b, margin, box_rows);
      rows.insert(rows.end(), box_rows.begin(), box_rows.end());
    }
    // Items [0, count) on all cores, each chunk's finds appended under the lock (sorted below).
    std::mutex merge;
    auto gather = [&](size_t count, size_t min_chunk, const auto& find) {
      for_each_chunk(count, [&](size_t first, size_t last) {
        std::vector<uint32_t> found;
        for (size_t k = first; k < last; ++k) find(k, found);
        const std::lock_guard<std::mutex> lock(merge);
        candidates.insert(candidates.end(), found.begin(), found.end());
      }, min_chunk);
    };
    gather(rows.size(), 4, [&](size_t r, std::vector<uint32_t>& found) {  // the rows' texels
      for (uint32_t k = rows[r].first; k < rows[r].second; ++k)
        if (within(grid->entry_position(k)) && !grid->is_displaced(grid->entry(k))) found.push_back(grid->entry(k));
    });
    const std::vector<uint32_t>& displaced = grid->displaced();  // up to an eighth of the texels
    gather(displaced.size(), 16384, [&](size_t k, std::vector<uint32_t>& found) {
      if (within(edited.gbuffer.texels[displaced[k]].position)) found.push_back(displaced[k]);
    });
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

namespace {

// A rotation, translation and uniform scale (no mirror): its 3x3 part M has M^T M = s^2 I. Returns s,
// or 0 when `m` is none.
double similarity_scale(const Matrix4d& m) {
  double gram[3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double sum = 0;
      for (int k = 0; k < 3; ++k) sum += m[size_t(a * 4 + k)] * m[size_t(b * 4 + k)];  // column a . column b
      gram[a][b] = sum;
    }
  const double s2 = (gram[0][0] + gram[1][1] + gram[2][2]) / 3;
  if (!(s2 > 0) || !std::isfinite(s2) || !(determinant3(m) > 0)) return 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (std::fabs(gram[a][b] - (a == b ? s2 : 0.0)) > 1e-6 * s2) return 0;
  return std::sqrt(s2);
}

// Whether a triangle of `lighting` outside the triangle ranges `skip` has bounds within `margin` of
// `p` (per axis, as WorldBox::contains grows a box). The BVH's leaves box a split triangle's
// fragments; its whole bounds are tested, so a triangle any part of which lies within reach is found.
bool triangle_within(const LightingScene& lighting, const Vec3& p, float margin,
                     const std::vector<std::pair<uint32_t, uint32_t>>& skip, std::vector<uint32_t>& stack) {
  const Bvh4& bvh = lighting.bvh;
  if (bvh.nodes.empty() || !lighting.source) return false;
  const Scene& scene = *lighting.source;  // the records' positions (refresh_moved_triangles_from_source)
  const Vec3 lo = p - Vec3{margin, margin, margin}, hi = p + Vec3{margin, margin, margin};
  auto skipped = [&](uint32_t t) {
    return std::any_of(skip.begin(), skip.end(), [&](const std::pair<uint32_t, uint32_t>& r) { return t >= r.first && t < r.second; });
  };
  stack.assign(1, 0);
  while (!stack.empty()) {
    const Bvh4Node& node = bvh.nodes[stack.back()];
    stack.pop_back();
    for (int c = 0; c < 4; ++c) {
      const uint32_t child = node.child[c];
      if (child == kBvhEmptyChild) continue;
      if (node.lo_x[c] > hi.x || node.hi_x[c] < lo.x || node.lo_y[c] > hi.y || node.hi_y[c] < lo.y || node.lo_z[c] > hi.z ||
          node.hi_z[c] < lo.z)
        continue;
      if (!(child & kBvhLeafBit)) {
        stack.push_back(child);
        continue;
      }
      const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
      for (uint32_t slot = first; slot < first + count; ++slot) {
        const uint32_t t = bvh.leaf_triangles[slot];
        if (t >= scene.triangle_count() || skipped(t)) continue;
        if (triangles_world_box(scene, t, 1).contains(p, margin)) return true;
      }
    }
  }
  return false;
}

}  // namespace

std::vector<uint32_t> texels_carried_rigidly(const PersistedScene& edited, const std::vector<uint32_t>& moved_texels,
                                             const std::vector<uint32_t>& moved_instances, const std::vector<Matrix4d>& deltas,
                                             const std::vector<WorldBox>& moved_boxes_before,
                                             const std::vector<WorldBox>& instance_boxes, const WorldBox& uninstanced,
                                             const LightingScene* edited_lighting) {
  std::vector<uint32_t> carried;
  if (moved_instances.size() != deltas.size() || moved_instances.size() != moved_boxes_before.size()) return carried;
  // Per moved instance: its move's inverse, its scale, and the other geometry's boxes near it.
  struct Move {
    Matrix4d inverse;
    double scale = 0;
    std::vector<WorldBox> others;
    std::vector<WorldBox> others_moved_before;  // the other moved instances' bounds before (not in the BVH)
    std::vector<std::pair<uint32_t, uint32_t>> own;  // its triangle range, which the finer test skips now
  };
  // The finer test's triangle ranges: an instance's, and every moved one's (skipped before the move).
  auto range_of = [&](uint32_t instance) {
    const Instance& i = edited.scene.instances[instance];
    return std::pair<uint32_t, uint32_t>{i.first_triangle, i.first_triangle + i.triangle_count};
  };
  std::vector<std::pair<uint32_t, uint32_t>> all_moved;
  if (edited_lighting)
    for (uint32_t m : moved_instances)
      if (m < edited.scene.instances.size()) all_moved.push_back(range_of(m));
  std::vector<Move> moves(moved_instances.size());
  std::vector<uint32_t> move_of(instance_boxes.size(), UINT32_MAX);
  float largest_reach = 0;
  for (uint32_t i : moved_texels) largest_reach = std::max(largest_reach, unocclude_reach(edited.gbuffer.texels[i]));
  for (size_t j = 0; j < moved_instances.size(); ++j) {
    const uint32_t k = moved_instances[j];
    if (k >= instance_boxes.size()) return {};
    move_of[k] = uint32_t(j);
    const std::optional<Matrix4d> inverse = affine_inverse(deltas[j]);
    moves[j].scale = inverse ? similarity_scale(deltas[j]) : 0;
    if (moves[j].scale == 0) continue;  // not rigid: every texel of it goes through unocclude again
    moves[j].inverse = *inverse;
    // Texels lie within their reach of their instance's bounds (a push moves at most that far).
    const float margin = 3 * largest_reach * float(std::max(1.0, 1 / moves[j].scale));
    WorldBox region = moved_boxes_before[j];
    region.grow(instance_boxes[k]);
    auto near_region = [&](const WorldBox& b) {
      return !b.empty() && b.lo.x <= region.hi.x + margin && b.hi.x >= region.lo.x - margin && b.lo.y <= region.hi.y + margin &&
             b.hi.y >= region.lo.y - margin && b.lo.z <= region.hi.z + margin && b.hi.z >= region.lo.z - margin;
    };
    for (size_t o = 0; o < instance_boxes.size(); ++o)
      if (o != k && near_region(instance_boxes[o])) moves[j].others.push_back(instance_boxes[o]);
    for (size_t o = 0; o < moved_instances.size(); ++o)
      if (o != j && near_region(moved_boxes_before[o])) {
        moves[j].others.push_back(moved_boxes_before[o]);
        moves[j].others_moved_before.push_back(moved_boxes_before[o]);
      }
    if (edited_lighting && k < edited.scene.instances.size()) moves[j].own.push_back(range_of(k));
    if (near_region(uninstanced)) moves[j].others.push_back(uninstanced);
  }
  std::vector<uint8_t> keep(moved_texels.size(), 0);
  for_each_chunk(moved_texels.size(), [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      const LiveTexel& texel = edited.gbuffer.texels[moved_texels[t]];
      if (texel.instance >= move_of.size() || move_of[texel.instance] == UINT32_MAX) continue;
      const Move& move = moves[move_of[texel.instance]];
      if (move.scale == 0) continue;
      // Where it is and where it was, each within twice the reach it had there (as unocclude_near_boxes tests).
      const float reach_now = unocclude_reach(texel), reach_before = reach_now / float(move.scale);
      const Vec3 before = transform_point(move.inverse, texel.position);
      bool near_other = std::any_of(move.others.begin(), move.others.end(), [&](const WorldBox& b) {
        return b.contains(texel.position, 2 * reach_now) || b.contains(before, 2 * reach_before);
      });
      if (near_other && edited_lighting) {
        // A box near is not yet geometry near (a street's box spans the city): the triangles
        // themselves, now (every instance's but its own, where they are now) and before (those
        // that did not move; the other moved instances' by their boxes before).
        thread_local std::vector<uint32_t> stack;
        near_other = std::any_of(move.others_moved_before.begin(), move.others_moved_before.end(),
                                 [&](const WorldBox& b) { return b.contains(before, 2 * reach_before); }) ||
                     triangle_within(*edited_lighting, texel.position, 2 * reach_now, move.own, stack) ||
                     triangle_within(*edited_lighting, before, 2 * reach_before, all_moved, stack);
      }
      keep[t] = !near_other;
    }
  }, 128);  // the texels near other geometry (BVH queries) cluster in index order: small chunks
  for (size_t t = 0; t < moved_texels.size(); ++t)
    if (keep[t]) carried.push_back(moved_texels[t]);
  return carried;
}

}  // namespace exitance
