// Which texels an edit changes most (seed 003 §4.7.3's refresh priorities): those near what it
// changed. A RefreshSession refreshes them first after a local edit.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/refresh/scene_edits.h"
#include "exitance/runtime/refresh/texel_grid.h"
#include "exitance/runtime/scene_file_conversion.h"

namespace exitance {

// Live texels (G-buffer indices of `edited`, ascending) within twice its half-diagonal (at least a
// tenth of the scene's extent) of a box of what the edit changed: a moved instance's bounds before and after, a point or spot light's
// position (before and after), the triangles of a material whose emission changed. Empty when the
// change is not local (a directional light, the sky), or nothing changed.
// `grid`: over `edited`'s G-buffer (the same texels at the same positions), to visit only the cells
// around the changed boxes; null (or over other texels): a pass over every texel. Same result.
std::vector<uint32_t> texels_near_change(const PersistedScene& edited, const Scene& before,
                                         const LightingScene& edited_lighting, const EditEffects& effects,
                                         const TexelGrid* grid = nullptr);

// What texels_near_change reads of the scene before the edit, kept by an edit made in place
// (apply_scene_edits_in_place) instead of a copy of that scene.
struct ChangeBefore {
  std::vector<Vec3> light_positions;                            // every light's, before the edit
  std::vector<WorldBox> moved_boxes_before, moved_boxes_after;  // per effects.moved_instances
};
// `marks` (with a grid; may be null): a scratch of one zero byte per texel, left zero, so that an
// edit neither allocates nor clears a megabyte (RefreshSession keeps one).
std::vector<uint32_t> texels_near_change(const PersistedScene& edited, const ChangeBefore& before,
                                         const LightingScene& edited_lighting, const EditEffects& effects,
                                         const TexelGrid* grid = nullptr, std::vector<uint8_t>* marks = nullptr);

}  // namespace exitance
