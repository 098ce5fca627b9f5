#include "exitance/runtime/view/path_traced_view.h"

#include <stdexcept>
#include <string>

#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/view/view_materials.h"
#include "exitance/runtime/view/view_shading.h"

namespace exitance::view {

CameraRayBatch camera_ray_batch(const ViewScene& view, const PinholeCamera& camera, int width, int height) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw std::invalid_argument("camera_ray_batch: image size " + std::to_string(width) + " x " + std::to_string(height) +
                                " is outside 1..16384");
  CameraRayBatch batch;
  batch.width = width;
  batch.height = height;
  const size_t pixels = size_t(width) * size_t(height);
  batch.gbuffer.pages.push_back({width, height, std::vector<float>(pixels, 1.0f)});
  batch.texel_of_pixel.assign(pixels, -1);
  batch.albedo.assign(pixels, Vec3(0));
  batch.constant.assign(pixels, Vec3(0));
  RayScratch scratch;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t p = size_t(y) * size_t(width) + size_t(x);
      const PrimaryRay ray = primary_ray(camera, x + 0.5, y + 0.5, width, height);
      const Vec3 d = ray.direction;
      const std::optional<SurfaceAtHit> hit = first_surface(view, ray.origin, d, scratch);
      if (!hit) {
        batch.constant[p] = sky_radiance(view.scene, d);
        continue;
      }
      if (hit->back_face_absorbs) continue;  // black, as the bake and the baked view treat it
      // The side the camera sees is the texel's front: on a double-sided surface's back both normals
      // turn towards the viewer, so the estimator gathers the light arriving on that side.
      const bool back = dot(d, hit->geometric_normal) > 0;
      LiveTexel texel;
      texel.page = 0;
      texel.x = uint32_t(x);
      texel.y = uint32_t(y);
      texel.position = hit->position;
      texel.geometric_normal = back ? -hit->geometric_normal : hit->geometric_normal;
      texel.shading_normal = hit->shading_normal;
      texel.albedo = hit->albedo;
      texel.instance = hit->instance;
      texel.triangle = hit->triangle;
      batch.texel_of_pixel[p] = int32_t(batch.gbuffer.texels.size());
      batch.gbuffer.texels.push_back(texel);
      batch.albedo[p] = hit->albedo;
      batch.constant[p] = hit->emission;
    }
  return batch;
}

PathTracedView render_path_traced_view(const ViewScene& view, const PinholeCamera& camera, int width, int height,
                                       const Integrator& integrator, const IntegratorSettings& settings) {
  const CameraRayBatch batch = camera_ray_batch(view, camera, width, height);
  PathTracedView out;
  out.estimate = integrator.bake(batch.gbuffer, settings);
  out.image.width = width;
  out.image.height = height;
  out.image.rgb.assign(batch.texel_of_pixel.size() * 3, 0.0f);
  out.variance.assign(batch.texel_of_pixel.size() * 3, 0.0f);
  for (size_t p = 0; p < batch.texel_of_pixel.size(); ++p) {
    Vec3 value = batch.constant[p], variance(0);
    if (const int32_t t = batch.texel_of_pixel[p]; t >= 0) {
      const Vec3 a = batch.albedo[p];
      value += a * out.estimate.mean_total(size_t(t));
      variance = a * a * out.estimate.variance_of_mean(size_t(t));
    }
    for (int c = 0; c < 3; ++c) {
      out.image.rgb[p * 3 + size_t(c)] = value[c];
      out.variance[p * 3 + size_t(c)] = variance[c];
    }
  }
  return out;
}

std::shared_ptr<const LightingScene> lighting_scene_of(const ViewScene& view) {
  PersistedScene persisted = restore_scene(view.scene);
  auto scene = std::make_shared<const Scene>(std::move(persisted.scene));
  return std::make_shared<const LightingScene>(build_lighting_scene(scene, to_bvh4(persisted.bvh)));
}

}  // namespace exitance::view
