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

// Tries, in order, the four views from outside the bounding box's upper corners towards its centre
// (the bounding sphere fills the image), then four from inside near an upper corner towards the
// opposite lower one (closed interiors show only the backs of their walls from outside). Returns the
// first whose test render is at least 40 % lit surface pixels, else the one with the most.
// The scene must have triangles.
AutomaticView choose_automatic_view(const view::ViewScene& scene);

}  // namespace exitance
