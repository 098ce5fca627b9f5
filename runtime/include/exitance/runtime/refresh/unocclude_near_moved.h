// After an edit moved instances (apply_scene_edits), the unocclude step again near them: a texel
// the moved object used to bury (a floor texel where a box stood) must come back to its surface
// point, and one it now buries must be pushed out, as a fresh bake would do.
#pragma once
#include <vector>

#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/refresh/scene_edits.h"
#include "exitance/runtime/refresh/texel_grid.h"
#include "exitance/runtime/scene_file_conversion.h"

namespace exitance {

// Every live texel within unocclude's reach (0.75 texel) of a box (the moved instances' bounds
// before and after the edit) goes back to its surface point (texel_surface.h, as the rasterizer
// places it) and through unocclude_texel on `edited_lighting` (the edited scene, its BVH refit), on
// the CPU, chunks of texels on threads. `grid` (may be null: a pass over every texel): over the
// G-buffer's texels, with every texel that moved since its build displaced (texel_grid.h); only its
// candidates are visited. Returns the texels reconsidered, ascending (the caller displaces them in
// its grid).
std::vector<uint32_t> unocclude_near_boxes(PersistedScene& edited, const std::vector<WorldBox>& boxes,
                                           const LightingScene& edited_lighting, const TexelGrid* grid);

}  // namespace exitance
