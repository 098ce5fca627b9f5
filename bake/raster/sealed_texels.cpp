#include "exitance/bake/raster/sealed_texels.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <functional>

#include "exitance/common/ray_offset.h"
#include "exitance/common/rng.h"
#include "exitance/common/sampling.h"

namespace exitance {

bool ends_on_dead_back_face(const Scene& scene, const Hit& hit, Vec3 direction) {
  if (!hit.found || !(dot(direction, hit.geometric_normal) > 0)) return false;
  const Material& m = scene.materials[scene.triangle_material[hit.triangle]];
  return !m.double_sided && m.alpha_mode == Material::AlphaMode::Opaque;
}

namespace {

// Whether a punctual light has a clear line to `origin`. glTF's optional `range` is not imported,
// so every point and spot light counts at any distance; spot cones are ignored (a light aimed
// away still counts): both only make the test keep more texels, never skip a lit one.
bool sees_a_punctual_light(const Scene& scene, const EmbreeScene& embree, Vec3 origin) {
  for (const PunctualLight& light : scene.lights) {
    if (light.type == PunctualLight::Type::Directional) {
      if (!embree.occluded(origin, -light.direction, INFINITY)) return true;
      continue;
    }
    const Vec3 to_light = light.position - origin;
    const float distance = length(to_light);
    if (!(distance > 0)) return true;
    if (!embree.occluded(origin, to_light / distance, distance * (1.0f - 1e-4f))) return true;
  }
  return false;
}

}  // namespace

// Why 16 + 240 rays: the first 16 (bake passes the enclosed-texel check's, already traced) reject
// almost every open texel at once, so the second set costs only where geometry closes over a
// texel. The second set is a jittered 16 x 15 grid over the square that sample_cosine_hemisphere
// warps to the hemisphere: an opening whose preimage in the square holds a whole grid cell (1/240
// = 0.42 % of the cosine-weighted hemisphere) is always found; a smaller or thinner one with a
// probability about proportional to its cosine-weighted size, so what can be missed is mostly
// light through gaps of well under 1 % of the view. Against that, a sealed texel traced at
// 128 spp would get 128 cosine rays of its own. --no-skip measures what was missed
// (bench/results/dead-work.md: nothing on the sample scenes).
SealedTexels find_sealed_texels(const Scene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
                                const std::vector<uint8_t>* closed, const FractionDone& progress) {
  SealedTexels result;
  result.sealed.assign(gbuffer.texels.size(), 0);
  tbb::combinable<size_t> candidates([] { return size_t(0); });
  ParallelProgress done(progress, gbuffer.texels.size());
  auto decide_texel = [&](size_t i) {
    const LiveTexel& t = gbuffer.texels[i];
    const Vec3 origin = offset_ray_origin(t.position, t.geometric_normal, embree.extent());
    auto closed_along = [&](float u1, float u2) {
      const Vec3 d = to_world(sample_cosine_hemisphere(u1, u2), t.geometric_normal);
      return ends_on_dead_back_face(scene, embree.intersect(origin, d, INFINITY), d);
    };
    Pcg32 rng = pcg_init(0x5EA1ED, i, 0);
    if (closed) {
      if (!(*closed)[i]) return;
    } else {
      for (int k = 0; k < kSealedFirstRays; ++k) {
        const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
        if (!closed_along(u1, u2)) return;
      }
    }
    ++candidates.local();
    for (int a = 0; a < kSealedConfirmRaysU; ++a)
      for (int b = 0; b < kSealedConfirmRaysV; ++b) {
        const float u1 = (float(a) + pcg_uniform(rng)) / float(kSealedConfirmRaysU);
        const float u2 = (float(b) + pcg_uniform(rng)) / float(kSealedConfirmRaysV);
        if (!closed_along(std::fmin(u1, 0x1.fffffep-1f), std::fmin(u2, 0x1.fffffep-1f))) return;
      }
    if (sees_a_punctual_light(scene, embree, origin)) return;
    result.sealed[i] = 1;
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, gbuffer.texels.size()), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) decide_texel(i);
    done.add(range.size());
  });
  result.candidates = candidates.combine(std::plus<size_t>());

  std::vector<size_t> live(scene.instances.size(), 0), sealed(scene.instances.size(), 0);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const uint32_t instance = gbuffer.texels[i].instance;
    if (instance >= live.size()) continue;
    ++live[instance];
    if (result.sealed[i]) ++sealed[instance];
  }
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) result.texels += result.sealed[i];
  for (size_t k = 0; k < live.size(); ++k)
    if (live[k] > 0 && sealed[k] == live[k]) ++result.instances;
  return result;
}

}  // namespace exitance
