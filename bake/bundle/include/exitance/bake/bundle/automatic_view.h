// The view bake --preview draws of a scene without glTF cameras (docs/bundle.md, "preview/"):
// candidate placements around and inside the scene's bounding box, the first that shows mostly lit
// surfaces.
#pragma once
#include "exitance/runtime/view/view_camera.h"
#include "exitance/runtime/view/view_scene.h"

namespace exitance {

struct AutomaticView {
  Vec3 look_from, look_at, up{0, 1, 0};
  double yfov = 0;
  double lit_fraction = 0;  // of a small test render's pixels: on a surface and not black
};

// Candidates: four views from outside the bounding box's upper corners towards its centre (the
// bounding sphere fills the image); of those in which at least 10 % of the pixels hit the scene and at
// least half of those are lit (not black), the one with the most lit pixels. Else (closed interiors
// show only the backs of their walls from outside) the best-scoring of those four and twelve views
// from inside: at mid-height 0.6 of the way to each corner looking across the centre or out towards
// the corner, and near each upper corner looking towards the opposite lower one. The score is the
// fraction of lit pixels, scaled down when the median surface is nearer than 15 % of the scene's
// largest extent (a close-up of a wall). Each candidate costs a 48 x 48 test render.
// The scene must have triangles.
AutomaticView choose_automatic_view(const view::ViewScene& scene);

}  // namespace exitance
