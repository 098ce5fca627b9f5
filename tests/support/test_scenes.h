// In-memory scenes for the analytic tests: quads and boxes with known geometry, and texels
// placed exactly where the closed-form answers are evaluated.
#pragma once
#include <cmath>
#include <vector>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance::testing {

inline uint32_t add_material(Scene& scene, Vec3 albedo, Vec3 emission = {0, 0, 0}, bool double_sided = false) {
  Material m;
  m.base_color = albedo;
  m.metallic = 0.0f;
  m.emission = emission;
  m.double_sided = double_sided;
  scene.materials.push_back(m);
  return uint32_t(scene.materials.size() - 1);
}

// Quad with corners c0, c0+u, c0+u+v, c0+v; front side is cross(u, v).
inline void add_quad(Scene& scene, Vec3 c0, Vec3 u, Vec3 v, uint32_t material) {
  if (scene.instances.empty() || scene.instances.back().name != "quads") {
    Instance instance;
    instance.name = "quads";
    instance.first_triangle = uint32_t(scene.triangle_count());
    scene.instances.push_back(instance);
  }
  const Vec3 n = normalize(cross(u, v));
  const Vec3 corners[4] = {c0, c0 + u, c0 + u + v, c0 + v};
  const Vec2 uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const int tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (const auto& t : tris) {
    for (int k : t) {
      scene.positions.push_back(corners[k]);
      scene.normals.push_back(n);
      scene.uv0.push_back(uvs[k]);
      scene.lightmap_uv.push_back(uvs[k]);
    }
    scene.triangle_material.push_back(material);
    scene.triangle_instance.push_back(uint32_t(scene.instances.size() - 1));
  }
  scene.instances.back().triangle_count = uint32_t(scene.triangle_count()) - scene.instances.back().first_triangle;
}

// Axis-aligned box [lo, hi] with all faces pointing inward (a closed room).
inline void add_inward_box(Scene& scene, Vec3 lo, Vec3 hi, uint32_t material) {
  const Vec3 d = hi - lo;
  const Vec3 ex{d.x, 0, 0}, ey{0, d.y, 0}, ez{0, 0, d.z};
  add_quad(scene, lo, ez, ex, material);                 // floor, normal +y
  add_quad(scene, lo + ey, ex, ez, material);            // ceiling, normal -y
  add_quad(scene, lo, ex, ey, material);                 // back wall z=lo, normal +z
  add_quad(scene, lo + ez, ey, ex, material);            // front wall z=hi, normal -z
  add_quad(scene, lo, ey, ez, material);                 // left wall x=lo, normal +x
  add_quad(scene, lo + ex, ez, ey, material);            // right wall x=hi, normal -x
}

inline LiveTexel texel_at(Vec3 position, Vec3 normal) {
  LiveTexel t;
  t.position = position;
  t.geometric_normal = normal;
  t.shading_normal = normal;
  t.albedo = {1, 1, 1};
  t.world_texel_size = 0.01f;
  return t;
}

// Aggregated z-score of a group of texels against expected per-texel values (one channel).
struct GroupComparison {
  double estimate = 0;
  double expected = 0;
  double standard_error = 0;
  double z() const { return standard_error > 0 ? (estimate - expected) / standard_error : 0.0; }
};

inline GroupComparison compare_group(const LightmapEstimate& estimate, const std::vector<size_t>& texels,
                                     const std::vector<double>& expected, int channel) {
  GroupComparison g;
  double variance = 0;
  for (size_t k = 0; k < texels.size(); ++k) {
    g.estimate += estimate.mean_total(texels[k])[channel];
    g.expected += expected[k];
    variance += estimate.variance_of_mean(texels[k])[channel];
  }
  const double n = double(texels.size());
  g.estimate /= n;
  g.expected /= n;
  g.standard_error = std::sqrt(variance) / n;
  return g;
}

}  // namespace exitance::testing
