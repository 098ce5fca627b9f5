#include "exitance/bake/raster/unocclude.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "exitance/runtime/unocclude_texel.h"

namespace exitance {

UnoccludeReport unocclude_texels(const EmbreeScene& embree, TexelGBuffer& gbuffer, const FractionDone& progress) {
  const ClosestHitQuery closest_hit = [&](const Vec3& origin, const Vec3& direction, float t_max) {
    const Hit hit = embree.intersect(origin, direction, t_max);
    return OccluderHit{hit.found, hit.distance, hit.geometric_normal};
  };
  tbb::combinable<size_t> moved([] { return size_t(0); });
  ParallelProgress done(progress, gbuffer.texels.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, gbuffer.texels.size()), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i)
      if (unocclude_texel(gbuffer.texels[i], embree.extent(), closest_hit)) ++moved.local();
    done.add(range.size());
  });
  return {moved.combine(std::plus<size_t>())};
}

}  // namespace exitance
