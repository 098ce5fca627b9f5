// Renders a view: one primary ray through each pixel centre, or N x N stratified rays per pixel
// (the centres of an N x N grid of sub-pixels) averaged in linear radiance; rows shared among threads.
#pragma once
#include <vector>

#include "exitance/runtime/view/view_camera.h"
#include "exitance/runtime/view/view_shading.h"

namespace exitance::view {

struct ViewImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3, linear, row 0 = top

  Vec3 pixel(int x, int y) const {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

struct ViewRenderOptions {
  int width = 512, height = 512;
  int samples_per_axis = 1;  // --aa N
  ViewMode mode = ViewMode::Lightmap;
  unsigned threads = 0;  // 0: one per hardware thread; at most one per row and 1024
};

// Throws std::invalid_argument for a size outside 1..16384 or samples per axis outside 1..16.
ViewImage render_view(const ViewScene& view, const PinholeCamera& camera, const ViewRenderOptions& options);

}  // namespace exitance::view
