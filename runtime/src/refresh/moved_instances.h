// What a node transform edit moves (scene_edits.h): the mesh instances and lights under the
// edited nodes, and the texels of those instances.
#pragma once
#include <string>
#include <utility>
#include <vector>

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

MovedGeometry move_under_edited_nodes(Scene& next, const Scene& old, const TexelGBuffer& gbuffer,
                                      const AtlasLayout& atlas, const std::vector<std::string>& edit_of_node);

}  // namespace exitance::refresh
