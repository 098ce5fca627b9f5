// What a node transform edit moves (scene_edits.h): the mesh instances and lights under the
// edited nodes, and the texels of those instances.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "exitance/runtime/world_box.h"

#include "exitance/runtime/refresh/scene_edits.h"

namespace exitance::refresh {

struct MovedGeometry {
  std::vector<uint32_t> instances;                     // ascending
  std::vector<uint32_t> lights;                        // ascending: position or direction changed
  std::vector<std::pair<size_t, LiveTexel>> texels;    // replacements for gbuffer.texels[first]
};

// `next` is `old` with edited node transforms (Scene::nodes); `edit_of_node[i]` labels the edit
// that set node i's transform (empty: none). Recomposes the world matrices, and for every instance
// whose world changed moves its triangles in `next` (positions, normals; corners 1 and 2 swapped,
// with their attributes, when the change mirrors) and sets its world; places the lights under
// edited nodes again; returns the texels of moved instances re-derived on `next`. Throws
// SceneEditError naming the responsible edit (the nearest edited ancestor) for a transform that is
// singular or not finite, collapses a triangle or a light's direction.
// Whether the edited node transforms of `next` change the world transform of a mesh instance
// (move_under_edited_nodes would move its triangles). Throws SceneEditError for a node hierarchy
// that does not compose.
bool moves_an_instance(const Scene& next, const std::vector<std::string>& edit_of_node);

// One instance's triangles (its range of every per-corner array the scene has), copied out of a
// scene to be moved and written back: what lets an edit be computed before anything is written.
struct MovedTriangles {
  uint32_t first = 0, count = 0;
  std::vector<Vec3> positions, normals, vertex_color, tangents;
  std::vector<Vec2> uv0, lightmap_uv;
  std::vector<float> vertex_alpha, tangent_signs;
  WorldBox box_before, box_after;  // the triangles' bounds before and after the move (plan_moves)
  static MovedTriangles of(const Scene& scene, uint32_t first, uint32_t count);
  void write_into(Scene& scene) const;  // the arrays the scene has; cannot throw
};

// What edited node transforms move, computed without writing geometry: per moved instance (ascending)
// its delta (new world x old world^-1) and its triangles as moved; the lights whose position or
// direction changed. `next` holds the edited nodes: its instances get their new world matrices and
// its lights are placed again; `geometry` holds the triangles as they are (it may be `next`).
// Throws SceneEditError as move_under_edited_nodes does.
struct PlannedMoves {
  std::vector<uint32_t> instances;
  std::vector<Matrix4d> delta;
  std::vector<MovedTriangles> triangles;
  std::vector<uint32_t> lights;
};
PlannedMoves plan_moves(Scene& next, const Scene& geometry, const std::vector<std::string>& edit_of_node);

// A texel of a moved instance: its index, which planned move carries it, whether the unocclude
// step had pushed it off its surface (read on the scene before the move), and its barycentrics on
// its triangle (lightmap UVs do not move: moved_texel reuses them unless the move mirrors, which
// reorders the triangle's corners).
struct MovingTexel {
  size_t index = 0;
  uint32_t move = 0;
  bool pushed = false;
  float b1 = 0, b2 = 0;
};
// The texels of the planned moves' instances, ascending: from `texels_by_instance` (texel_start[k]
// .. texel_start[k + 1] lists instance k's texels) when given, else by a pass over the G-buffer.
// Throws SceneEditError for an atlas without a rectangle per instance or a texel naming a page or
// triangle the scene does not have.
std::vector<MovingTexel> moving_texels(const PlannedMoves& planned, const Scene& before, const TexelGBuffer& gbuffer,
                                       const AtlasLayout& atlas, const std::vector<uint32_t>* texel_start,
                                       const std::vector<uint32_t>* texels_by_instance);
// The texel re-derived on `next` (the scene with the moved triangles written).
LiveTexel moved_texel(const LiveTexel& texel, const MovingTexel& moving, const PlannedMoves& planned, const Scene& next,
                      const TexelGBuffer& gbuffer, const AtlasLayout& atlas);

MovedGeometry move_under_edited_nodes(Scene& next, const Scene& old, const TexelGBuffer& gbuffer,
                                      const AtlasLayout& atlas, const std::vector<std::string>& edit_of_node);

}  // namespace exitance::refresh
