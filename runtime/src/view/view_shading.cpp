#include "exitance/runtime/view/view_shading.h"

#include <algorithm>
#include <limits>

#include "exitance/common/material.h"
#include "exitance/runtime/core/bvh4_walk.h"
#include "exitance/runtime/view/view_materials.h"

namespace exitance::view {
namespace {

Vec3 to_vec3(const formats::Float3& f) { return {f[0], f[1], f[2]}; }

SurfaceAtHit surface_at(const ViewScene& view, const Bvh4WalkHit& hit, Vec3 direction) {
  const formats::SceneTriangles& tris = view.scene.triangles;
  const size_t t = hit.triangle, c = 3 * t;
  const float b1 = float(hit.b1), b2 = float(hit.b2), b0 = 1 - b1 - b2;
  const Vec3 p0 = to_vec3(tris.positions[c]), p1 = to_vec3(tris.positions[c + 1]), p2 = to_vec3(tris.positions[c + 2]);
  SurfaceAtHit s;
  s.position = p0 * b0 + p1 * b1 + p2 * b2;
  s.geometric_normal = normalize(cross(p1 - p0, p2 - p0));
  // As texel_surface.h derives a texel's normal: the interpolated one unless it is zero or points
  // more than ~87 degrees away from the geometric normal.
  Vec3 n = to_vec3(tris.normals[c]) * b0 + to_vec3(tris.normals[c + 1]) * b1 + to_vec3(tris.normals[c + 2]) * b2;
  const float len = length(n);
  n = len > 0 ? n / len : s.geometric_normal;
  if (!(dot(n, s.geometric_normal) > 0.05f)) n = s.geometric_normal;
  const formats::MaterialRecord& m = view.scene.materials[tris.material[t]];
  const bool front = dot(direction, s.geometric_normal) < 0;
  s.back_face_absorbs = !front && !m.double_sided;
  s.interpolated_normal = n;
  s.mapped_normal = surface_normal(view.scene, uint32_t(t), b1, b2, n);
  s.shading_normal = front || !m.double_sided ? s.mapped_normal : -s.mapped_normal;
  s.instance = tris.instance[t];
  s.triangle = uint32_t(t);
  s.albedo = surface_albedo(view.scene, s.triangle, b1, b2);
  s.emission = front || m.double_sided ? surface_emission(view.scene, s.triangle, b1, b2) : Vec3(0);
  s.opacity = surface_opacity(view.scene, s.triangle, b1, b2);
  const formats::Float2 uv0 = tris.lightmap_uv[c], uv1 = tris.lightmap_uv[c + 1], uv2 = tris.lightmap_uv[c + 2];
  s.lightmap_uv = {uv0[0] * b0 + uv1[0] * b1 + uv2[0] * b2, uv0[1] * b0 + uv1[1] * b1 + uv2[1] * b2};
  return s;
}

Vec3 probes_irradiance_over_pi(const ViewScene& view, const SurfaceAtHit& s) {
  if (!view.bundle.has_probes()) return Vec3(0);
  const loader::ProbeIrradianceResult e = view.bundle.probe_irradiance_over_pi(
      {s.position.x, s.position.y, s.position.z}, {s.shading_normal.x, s.shading_normal.y, s.shading_normal.z});
  return {e.irradiance_over_pi[0], e.irradiance_over_pi[1], e.irradiance_over_pi[2]};
}

// The lightmap's E/pi; with L1 SH layers, at the mapped normal n rather than the normal n0 the texels
// were baked for (docs/bundle.md, "Directional layers"): E(n)/pi = RGB + L1 . (n - n0), clamped at 0.
// n0 between texel centres is the interpolated normal, as each texel's n0 is it at its centre; the
// lightmap holds the front side's irradiance, so both are taken on the front.
Vec3 lightmap_irradiance_over_pi(const ViewScene& view, const SurfaceAtHit& s) {
  const loader::Rgb e = view.bundle.lightmap(s.instance, s.lightmap_uv);
  const Vec3 rgb{e[0], e[1], e[2]};
  const Vec3 d = s.mapped_normal - s.interpolated_normal;
  if (!view.has_sh1_layers || (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f)) return rgb;
  float l1[9];
  for (int k = 0; k < 9; ++k) l1[k] = view.bundle.lightmap_channel(s.instance, kSh1Channels[k], s.lightmap_uv);
  const auto channel = [&](int c, float base) { return std::max(0.0f, base + l1[c] * d.x + l1[3 + c] * d.y + l1[6 + c] * d.z); };
  return {channel(0, rgb.x), channel(1, rgb.y), channel(2, rgb.z)};
}

}  // namespace

std::optional<ViewMode> parse_view_mode(const std::string& name) {
  for (ViewMode m : {ViewMode::Lightmap, ViewMode::Probes, ViewMode::Albedo, ViewMode::Normal, ViewMode::Error})
    if (name == view_mode_name(m)) return m;
  return std::nullopt;
}

const char* view_mode_name(ViewMode mode) {
  switch (mode) {
    case ViewMode::Lightmap: return "lightmap";
    case ViewMode::Probes: return "probes";
    case ViewMode::Albedo: return "albedo";
    case ViewMode::Normal: return "normal";
    case ViewMode::Error: return "error";
  }
  return "?";
}

namespace {

// The nearest surface along the ray that is not in `passed` (surfaces the ray already went through).
std::optional<SurfaceAtHit> nearest_surface_not_in(const ViewScene& view, Vec3 origin, Vec3 direction, RayScratch& scratch,
                                                   const std::vector<uint32_t>& passed) {
  const formats::SceneFile& scene = view.scene;
  const auto corners = [&](uint32_t t, Vec3& p0, Vec3& p1, Vec3& p2) {
    p0 = to_vec3(scene.triangles.positions[3 * size_t(t)]);
    p1 = to_vec3(scene.triangles.positions[3 * size_t(t) + 1]);
    p2 = to_vec3(scene.triangles.positions[3 * size_t(t) + 2]);
    // A degenerate triangle is never hit: the walk then finds the next surface along the same ray,
    // without moving the origin (no offset to tune, no self-hit).
    if (std::find(passed.begin(), passed.end(), t) != passed.end()) p1 = p2 = p0;
  };
  const Bvh4WalkHit hit =
      bvh4_closest_hit</*kNearestChildFirst=*/true>(scene.bvh.nodes.data(), scene.bvh.nodes.size(), scene.bvh.leaf_triangles.data(), corners, origin,
                       direction, std::numeric_limits<float>::infinity(), scratch.stack);
  if (!hit.found) return std::nullopt;
  return surface_at(view, hit, direction);
}

// At most this many surfaces are passed through or composited per primary ray.
constexpr size_t kMaxLayers = 16;

Vec3 shade_surface(const ViewScene& view, ViewMode mode, const SurfaceAtHit& s) {
  switch (mode) {
    case ViewMode::Albedo: return s.albedo;
    case ViewMode::Normal: return s.shading_normal * 0.5f + Vec3(0.5f);
    case ViewMode::Error: {
      if (!view.instance_has_texels[s.instance]) return Vec3(0);
      return Vec3(view.bundle.lightmap_channel(s.instance, kErrorChannel, s.lightmap_uv));
    }
    case ViewMode::Lightmap:
    case ViewMode::Probes: {
      if (s.back_face_absorbs) return Vec3(0);
      const bool from_lightmap = mode == ViewMode::Lightmap && view.instance_has_texels[s.instance];
      const Vec3 e_over_pi = from_lightmap ? lightmap_irradiance_over_pi(view, s) : probes_irradiance_over_pi(view, s);
      return s.albedo * e_over_pi + s.emission;
    }
  }
  return Vec3(0);
}

}  // namespace

std::optional<SurfaceAtHit> first_surface(const ViewScene& view, Vec3 origin, Vec3 direction, RayScratch& scratch) {
  std::vector<uint32_t> passed;
  while (passed.size() < kMaxLayers) {
    std::optional<SurfaceAtHit> hit = nearest_surface_not_in(view, origin, direction, scratch, passed);
    if (!hit || hit->opacity > 0.0f) return hit;
    passed.push_back(hit->triangle);  // a MASK cut-out or a fully transparent BLEND surface
  }
  return std::nullopt;
}

Vec3 shade_primary_ray(const ViewScene& view, ViewMode mode, Vec3 origin, Vec3 direction, RayScratch& scratch) {
  const bool lit_mode = mode == ViewMode::Lightmap || mode == ViewMode::Probes;
  // Front to back: each surface adds its shade times its opacity times what the nearer ones let
  // through (alpha blending, "over"); OPAQUE and MASK surfaces end the ray.
  std::vector<uint32_t> passed;
  Vec3 result(0);
  float transmitted = 1.0f;
  while (passed.size() < kMaxLayers) {
    const std::optional<SurfaceAtHit> hit = nearest_surface_not_in(view, origin, direction, scratch, passed);
    if (!hit) return result + (lit_mode ? sky_radiance(view.scene, direction) : Vec3(0)) * transmitted;
    if (hit->opacity > 0.0f) result = result + shade_surface(view, mode, *hit) * (transmitted * hit->opacity);
    transmitted *= 1.0f - hit->opacity;
    if (!(transmitted > 0.0f)) break;
    passed.push_back(hit->triangle);
  }
  return result;
}

}  // namespace exitance::view
