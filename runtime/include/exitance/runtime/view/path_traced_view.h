// The path-traced view (issue 14): the ground truth a baked view is compared with. Each pixel centre's
// ray finds its first surface with the view's BVH walk; those surface points become one batch of
// "texels" of a pixel-sized G-buffer, and a lighting backend (the CPU reference or Vulkan, through
// the Integrator interface) estimates E/pi there exactly as for lightmap texels. Pixel = albedo x
// E/pi + emission; the sky on a miss; 0 on the back of a single-sided surface (docs/view.md).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/view/view_camera.h"
#include "exitance/runtime/view/view_render.h"
#include "exitance/runtime/view/view_scene.h"

namespace exitance::view {

// The camera-ray batch: one live texel per pixel whose centre ray meets a face that receives light.
struct CameraRayBatch {
  int width = 0, height = 0;
  TexelGBuffer gbuffer;                 // one page of width x height; texel (x, y) = pixel (x, y)
  std::vector<int32_t> texel_of_pixel;  // per pixel: its texel, or -1 (a miss or an absorbing back face)
  std::vector<Vec3> albedo;             // per pixel: what multiplies E/pi (0 where there is no texel)
  std::vector<Vec3> constant;           // per pixel: emission, the sky on a miss, 0 on an absorbing back face
};

// Throws std::invalid_argument for a size outside 1..16384.
CameraRayBatch camera_ray_batch(const ViewScene& view, const PinholeCamera& camera, int width, int height);

struct PathTracedView {
  ViewImage image;
  std::vector<float> variance;  // per pixel and channel: the variance of the pixel's mean (albedo^2 Var[E/pi])
  LightmapEstimate estimate;    // the backend's estimate over the batch's texels
};

// `integrator` must light `view`'s scene (lighting_scene_of(view) or the bake's own). Settings as for
// Integrator::bake; the batch has no atlas rectangles, so the per-bounce mode would treat every hit
// as texel-less (use IntegratorMode::Path, the reference estimator).
PathTracedView render_path_traced_view(const ViewScene& view, const PinholeCamera& camera, int width, int height,
                                       const Integrator& integrator, const IntegratorSettings& settings);

// The bundle's scene.bin as the lighting backends read it (its own BVH4, no rebuild).
std::shared_ptr<const LightingScene> lighting_scene_of(const ViewScene& view);

}  // namespace exitance::view
