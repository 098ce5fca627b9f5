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
// `carried` (may be null; ascending): texels left as they are (texels_carried_rigidly).
std::vector<uint32_t> unocclude_near_boxes(PersistedScene& edited, const std::vector<WorldBox>& boxes,
                                           const LightingScene& edited_lighting, const TexelGrid* grid,
                                           const std::vector<uint32_t>* carried = nullptr);

// Of `moved_texels` (ascending: the texels of the instances an edit moved, already moved), those
// whose unocclude result the move carried with them (moved_texel moves a push rigidly): a move
// that is a rotation, translation and uniform scale keeps every texel's distances to its own
// instance's triangles (scaled with its reach), so unless other geometry lies within reach where
// the texel is now or where it was, a fresh unocclude step gives the carried push again: up to
// rounding after a translation or scale; after a rotation, past the same back face but maybe
// elsewhere within reach (the step's 8 sideways rays keep their world directions), and the carried
// texel is one the step leaves where it is (tests/runtime/carried_texels_test.cpp). Other geometry: every other instance's triangle bounds (`instance_boxes`, after the edit;
// other moved instances also by `moved_boxes_before`) and those of triangles in no instance.
// `moved_instances`, `deltas` (world after * world before^-1) and `moved_boxes_before` per moved
// instance, as InPlaceEdits lists them. `edited_lighting` (may be null): the edited scene with its
// BVH refit; where a texel lies within reach of another instance's box (or of the triangles in no
// instance), its triangles are tested instead (a street floor's box spans a city), which carries
// more texels. A moved block in the open city: 10 381 texels moved, 9 333 carried by boxes alone.
std::vector<uint32_t> texels_carried_rigidly(const PersistedScene& edited, const std::vector<uint32_t>& moved_texels,
                                             const std::vector<uint32_t>& moved_instances, const std::vector<Matrix4d>& deltas,
                                             const std::vector<WorldBox>& moved_boxes_before,
                                             const std::vector<WorldBox>& instance_boxes, const WorldBox& uninstanced,
                                             const LightingScene* edited_lighting = nullptr);

}  // namespace exitance
