#include "exitance/bake/raster/geometry_checks.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "exitance/bake/raster/sealed_texels.h"
#include "exitance/runtime/material_eval.h"
#include "exitance/common/ray_offset.h"
#include "exitance/common/rng.h"
#include "exitance/common/sampling.h"

namespace exitance {
namespace {

constexpr int kHemisphereRays = kSealedFirstRays;
constexpr int kLightRays = 64;
// A texel none of whose first kScreenRays rays hits a back face is open: one that sees back faces
// in a fraction p of its cosine-weighted hemisphere passes this screen with probability (1 - p)^4,
// at most 1/16 for the p = 0.5 where the 16-ray majority below is itself a coin toss (it calls
// such a texel enclosed with probability 0.40). It halves the rays of an open texel (4, not the
// 8 the majority needs to be decided): the checks were the bake's largest stage after lighting
// and writing on the open city (12.9 s of 9.6 M texels on 2 cores, 78 % of it in Embree).
constexpr int kScreenRays = 4;

bool hits_back_face(const Hit& hit, Vec3 direction) { return hit.found && dot(direction, hit.geometric_normal) > 0; }

}  // namespace

GeometryCheckReport check_scene_geometry(const Scene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
                                         const FractionDone& progress) {
  GeometryCheckReport report;
  report.closed_texels.assign(gbuffer.texels.size(), 0);
  tbb::combinable<size_t> enclosed([] { return size_t(0); }), coplanar([] { return size_t(0); });
  ParallelProgress done(progress, gbuffer.texels.size());
  auto check_texel = [&](size_t i) {
    const LiveTexel& t = gbuffer.texels[i];
    const Vec3 origin = offset_ray_origin(t.position, t.geometric_normal, embree.extent());
    Pcg32 rng = pcg_init(0xC0FFEE, i, 0);
    int back = 0, dead = 0;
    for (int k = 0; k < kHemisphereRays; ++k) {
      const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
      const Vec3 d = to_world(sample_cosine_hemisphere(u1, u2), t.geometric_normal);
      const Hit hit = embree.intersect(origin, d, INFINITY);
      if (hits_back_face(hit, d)) ++back;
      if (ends_on_dead_back_face(scene, hit, d)) ++dead;
      // Stop once both answers are settled: a ray that did not end on a dead back face means not
      // closed, and the majority test is decided when the rays left cannot change it or the
      // screen has called the texel open. Each
      // texel draws from its own sequence, so stopping early changes no other texel's rays.
      const int left = kHemisphereRays - 1 - k;
      const bool closed_decided = dead < k + 1;
      const bool screened_open = k + 1 == kScreenRays && back == 0;
      const bool enclosed_decided =
          screened_open || back * 2 > kHemisphereRays || (back + left) * 2 <= kHemisphereRays;
      if (closed_decided && enclosed_decided) break;
    }
    if (back * 2 > kHemisphereRays) ++enclosed.local();
    report.closed_texels[i] = dead == kHemisphereRays ? 1 : 0;
    // Look back through the texel: another instance's surface within a few offsets, facing the
    // same way, overlaps it in the same plane (opposite-facing contact, a box on a floor, is fine).
    // Every hit within reach is tested, not only the closest: the floor under a box meets both the
    // box's bottom face and a doubled floor at one distance, and which of them Embree reports as
    // closest differs between its per-CPU kernels.
    const float reach = 4.0f * length(origin - t.position) + 1e-4f * t.world_texel_size;
    const bool overlapped = embree.any_hit_where(origin, -t.geometric_normal, reach, [&](const Hit& other) {
      if (scene.triangle_instance[other.triangle] == t.instance) return false;
      // Hits on the other surface's border are neighbours touching edge to edge, not overlaps.
      const bool inside = other.b1 > 1e-3f && other.b2 > 1e-3f && 1.0f - other.b1 - other.b2 > 1e-3f;
      return inside && dot(other.geometric_normal, t.geometric_normal) > 0.999f;
    });
    if (overlapped) ++coplanar.local();
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, gbuffer.texels.size()), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) check_texel(i);
    done.add(range.size());
  });
  report.enclosed_texels = enclosed.combine(std::plus<size_t>());
  report.coplanar_texels = coplanar.combine(std::plus<size_t>());

  for (size_t l = 0; l < scene.lights.size(); ++l) {
    const PunctualLight& light = scene.lights[l];
    if (light.type == PunctualLight::Type::Directional) continue;
    Pcg32 rng = pcg_init(0x11647, l, 0);
    int back = 0, escaped = 0;
    for (int k = 0; k < kLightRays; ++k) {
      const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
      const Vec3 d = uniform_sphere(u1, u2);
      const Hit hit = embree.intersect(light.position, d, INFINITY);
      if (!hit.found) ++escaped;
      else if (hits_back_face(hit, d)) ++back;
    }
    if (escaped == 0 && back == kLightRays) report.enclosed_lights.push_back(int(l));
  }

  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    if (!is_emissive(scene, t)) continue;
    if (!(triangle_area(scene, t) > 0.0f)) ++report.unsampled_emitters;
  }
  return report;
}

std::vector<std::string> describe_geometry_problems(const GeometryCheckReport& report, const Scene& scene,
                                                    const std::string& file) {
  std::vector<std::string> lines;
  if (report.enclosed_texels)
    lines.push_back(file + ": " + std::to_string(report.enclosed_texels) +
                    " texels see mostly back faces (inside or under geometry); they will be dark");
  if (report.coplanar_texels)
    lines.push_back(file + ": " + std::to_string(report.coplanar_texels) +
                    " texels lie on coplanar overlapping surfaces (z-fighting); results there depend on which wins");
  for (int l : report.enclosed_lights)
    lines.push_back(file + ": light " + std::to_string(l) +
                    (scene.lights[size_t(l)].name.empty() ? "" : " '" + scene.lights[size_t(l)].name + "'") +
                    " is enclosed by geometry: it lights nothing outside");
  if (report.unsampled_emitters)
    lines.push_back(file + ": " + std::to_string(report.unsampled_emitters) +
                    " emissive triangles have zero area and emit nothing");
  return lines;
}

}  // namespace exitance
