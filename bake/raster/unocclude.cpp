#include "exitance/bake/raster/unocclude.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "exitance/common/ray_offset.h"
#include "exitance/common/sampling.h"

namespace exitance {

UnoccludeReport unocclude_texels(const EmbreeScene& embree, TexelGBuffer& gbuffer) {
  constexpr int kDirections = 8;
  tbb::combinable<size_t> moved([] { return size_t(0); });
  tbb::parallel_for(size_t(0), gbuffer.texels.size(), [&](size_t i) {
    LiveTexel& texel = gbuffer.texels[i];
    const float reach = texel.world_texel_size * 0.75f;  // a texel's half-diagonal, slightly more
    if (!(reach > 0)) return;
    Vec3 t, b;
    orthonormal_basis(texel.geometric_normal, t, b);
    // Start a hair above the surface; look sideways, tilted slightly up, within the texel footprint.
    const Vec3 origin = offset_ray_origin(texel.position, texel.geometric_normal, embree.extent());
    float closest = reach;
    Vec3 push_to{};
    bool push = false;
    for (int k = 0; k < kDirections; ++k) {
      const float phi = 2.0f * kPi * (float(k) + 0.5f) / float(kDirections);
      const Vec3 dir = normalize(t * std::cos(phi) + b * std::sin(phi) + texel.geometric_normal * 0.05f);
      const Hit hit = embree.intersect(origin, dir, closest);
      if (!hit.found) continue;
      closest = hit.distance;
      // Seeing a back face this close means the centre sits inside or behind that surface.
      push = dot(dir, hit.geometric_normal) > 0;
      if (push) {
        const Vec3 p = origin + dir * hit.distance;
        const Vec3 beyond = offset_ray_origin(p, hit.geometric_normal, embree.extent());  // just past the back face
        push_to = beyond + dir * (texel.world_texel_size * 0.01f);
      }
    }
    if (push) {
      // Keep the texel on its own plane: drop the tilt we added along the normal.
      const float height = dot(push_to - texel.position, texel.geometric_normal);
      texel.position = push_to - texel.geometric_normal * height;
      ++moved.local();
    }
  });
  return {moved.combine(std::plus<size_t>())};
}

}  // namespace exitance
