#include "exitance/runtime/core/lighting_scene.h"

#include "exitance/common/light_layers.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "exitance/common/material.h"
#include "exitance/common/punctual_light.h"
#include "exitance/common/sampling.h"
#include "exitance/runtime/core/bvh4_refit.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/distribution_1d.h"
#include "exitance/runtime/material_eval.h"

namespace exitance {
namespace {

// A distribution's CDF for a GPU buffer, which must hold at least two entries.
std::vector<double> padded_cdf(const Distribution1D& distribution) {
  std::vector<double> cdf = distribution.cdf();
  if (cdf.size() < 2) cdf.resize(2, 0.0);
  return cdf;
}

// A BVH from elsewhere (scene.bin, the offline stage) must only reference triangles that exist;
// triangles it leaves out (non-finite vertices) are never hit, as on the CPU reference.
void check_bvh_references(const Bvh4& bvh, size_t triangle_count) {
  for (uint32_t t : bvh.leaf_triangles)
    if (t >= triangle_count)
      throw std::invalid_argument("BVH leaf references triangle " + std::to_string(t) + " of " +
                                  std::to_string(triangle_count));
}

// The material varies over a surface (textures) or over its hits (MASK, BLEND): the CPU reference
// evaluates it per point from the source Scene.
bool varies_per_point(const Material& m) {
  return m.base_color_texture.texture >= 0 || m.emissive_texture.texture >= 0 ||
         m.alpha_mode != Material::AlphaMode::Opaque;
}

GpuMaterial material_record(const Material& m) {
  const Vec3 emission = max_component(m.emission) > 0.0f ? m.emission : Vec3{0, 0, 0};
  GpuMaterial g;
  g.albedo_double_sided = Vec4(diffuse_albedo_of(m.base_color, m.metallic), m.double_sided ? 1.0f : 0.0f);
  g.emission = Vec4(emission, 0.0f);
  return g;
}

GpuPunctualLight punctual_record(const PunctualLight& light) {
  const uint32_t type = light.type == PunctualLight::Type::Spot          ? kPunctualSpot
                        : light.type == PunctualLight::Type::Directional ? kPunctualDirectional
                                                                         : kPunctualPoint;
  GpuPunctualLight g;
  g.position_type = Vec4(light.position, uintBitsToFloat(type));
  g.direction_cos_inner = Vec4(light.direction, light.cos_inner);
  g.intensity_cos_outer = Vec4(light.intensity, light.cos_outer);
  return g;
}

// Point 4 pi I, spot 2 pi (1 - cos_outer) I, directional pi r^2 E.
double punctual_power(const PunctualLight& light, float radius) {
  const double intensity = luminance(light.intensity);
  switch (light.type) {
    case PunctualLight::Type::Spot: return 2.0 * kPi * (1.0 - light.cos_outer) * intensity;
    case PunctualLight::Type::Directional: return kPi * double(radius) * double(radius) * intensity;
    default: return 4.0 * kPi * intensity;
  }
}

void set_emitter_distribution(LightingScene& lighting, const std::vector<double>& powers, std::vector<float> areas);

// Per material: the luminance of its mean emission, x2 when double sided (an emitter's power is
// its area times this). Once per call: an emissive texture's mean reads the whole image.
std::vector<double> emission_power_per_area(const Scene& scene) {
  std::vector<double> out(scene.materials.size());
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    Vec3 mean = m.emission;
    if (m.emissive_texture.texture >= 0) mean = mean * texture_mean(scene.textures[size_t(m.emissive_texture.texture)]);
    out[i] = double(luminance(mean)) * (m.double_sided ? 2.0 : 1.0);
  }
  return out;
}

// Every material record's power per area (GpuMaterial::emitter_power).
void set_material_powers(LightingScene& lighting, const std::vector<double>& per_area) {
  for (size_t i = 0; i < lighting.materials.size(); ++i) lighting.materials[i].emitter_power = Vec4(float(per_area[i]), 0.0f, 0.0f, 0.0f);
}

// Emitters by power (area x luminance of the mean emission, x2 when double sided), each flagged on
// its triangle's record, and on every material's record its power per area: with the total's
// inverse, the area density under that choice, which NEE's MIS needs at any hit on an emitter
// (scene_access.h scene_triangle_area_pdf).
void build_emitter_distribution(LightingScene& lighting) {
  const Scene& scene = *lighting.source;
  const std::vector<double> per_area = emission_power_per_area(scene);
  set_material_powers(lighting, per_area);
  lighting.emitter_triangles.clear();
  for (GpuTriangle& g : lighting.triangles) g.p1_emitter.w = 0.0f;
  std::vector<double> powers;
  std::vector<float> areas;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    if (!is_emissive(scene, t)) continue;
    const float area = triangle_area(scene, t);
    const double power = double(area) * per_area[scene.triangle_material[t]];
    if (!(power > 0) || !(area > 0)) continue;  // zero-area or black emitters can never be hit usefully
    lighting.emitter_triangles.push_back(t);
    lighting.triangles[t].p1_emitter.w = 1.0f;
    powers.push_back(power);
    areas.push_back(area);
  }
  set_emitter_distribution(lighting, powers, std::move(areas));
}

// After emitters moved (their areas may change by rounding or a scale, the set cannot: emission
// is the material's, and a move that collapses a triangle is refused): the same distribution as
// build_emitter_distribution from the emitters alone. False, nothing changed, when a listed
// emitter no longer qualifies (build_emitter_distribution then).
bool refresh_emitter_powers(LightingScene& lighting, const std::vector<uint32_t>& moved) {
  const Scene& scene = *lighting.source;
  const std::vector<double> per_area = emission_power_per_area(scene);
  const std::vector<uint32_t>& emitters = lighting.emitter_triangles;
  std::vector<float> areas = lighting.emitter_areas;
  if (areas.size() != emitters.size()) {
    areas.resize(emitters.size());
    for (size_t i = 0; i < emitters.size(); ++i) areas[i] = triangle_area(scene, emitters[i]);
  } else {  // both ascend: the moved emitters' areas again, the others' are the same bits
    for (size_t i = 0, k = 0; i < emitters.size() && k < moved.size();) {
      if (emitters[i] < moved[k]) ++i;
      else if (moved[k] < emitters[i]) ++k;
      else areas[i++] = triangle_area(scene, moved[k++]);
    }
  }
  std::vector<double> powers(emitters.size());
  std::atomic<bool> qualify{true};
  for_each_chunk(emitters.size(), [&](size_t first, size_t last) {  // a city holds tens of thousands of emitters
    for (size_t i = first; i < last; ++i) {
      const double area = areas[i];
      powers[i] = area * per_area[scene.triangle_material[emitters[i]]];
      if (!(powers[i] > 0) || !(area > 0)) qualify.store(false, std::memory_order_relaxed);
    }
  }, 4096);
  if (!qualify.load()) return false;
  set_emitter_distribution(lighting, powers, std::move(areas));
  return true;
}

// After materials' emission was edited: when every listed material emitted before and still does
// (so the emitter list is the same), the same distribution as build_emitter_distribution from the
// emitters alone: the materials' records take their power per area, every emitter's power its kept
// area times its material's; no triangle record changes. A city's 19 552 emitters instead of a pass
// over every triangle. False, nothing changed, when a listed material starts or stops emitting.
bool refresh_edited_emitters(LightingScene& lighting, const std::vector<uint32_t>& materials) {
  const Scene& scene = *lighting.source;
  const std::vector<uint32_t>& emitters = lighting.emitter_triangles;
  if (lighting.emitter_areas.size() != emitters.size()) return false;
  const std::vector<double> per_area = emission_power_per_area(scene);
  // Emitting now, as build_emitter_distribution qualifies an emitter (its area > 0 aside)...
  for (uint32_t m : materials)
    if (!(max_component(scene.materials[m].emission) > 0.0f && per_area[m] > 0)) return false;
  // ... and before: a material emitting now but not before has no emitter in the list (its
  // triangles would join it).
  std::vector<bool> listed(scene.materials.size(), false);
  for (uint32_t t : emitters) listed[scene.triangle_material[t]] = true;
  for (uint32_t m : materials)
    if (!listed[m]) return false;
  std::vector<double> powers(emitters.size());
  for_each_chunk(emitters.size(), [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i) powers[i] = double(lighting.emitter_areas[i]) * per_area[scene.triangle_material[emitters[i]]];
  }, 4096);
  set_material_powers(lighting, per_area);
  set_emitter_distribution(lighting, powers, lighting.emitter_areas);
  return true;
}

// The emitter CDF over `powers` (per lighting.emitter_triangles) and the total's inverse. An
// emitter's pick probability over its area is its material's power per area over the total: a move
// (areas, hence the total, change) leaves every emitter's record as it is.
void set_emitter_distribution(LightingScene& lighting, const std::vector<double>& powers, std::vector<float> areas) {
  const Distribution1D emitters(powers);
  lighting.emitter_cdf = padded_cdf(emitters);
  // Finite even for a total below the smallest float's inverse (0 x it stays 0 on a non-emitter).
  lighting.emitter_inverse_power =
      emitters.total() > 0 ? float(std::min(1.0 / emitters.total(), double(std::numeric_limits<float>::max()))) : 0.0f;
  lighting.emitter_areas = std::move(areas);
}

// Punctual lights by power. An all-zero distribution never samples (pmf 0 -> probability 0).
void build_punctual_distribution(LightingScene& lighting) {
  std::vector<double> powers;
  const float radius = scene_radius(lighting);
  lighting.punctual_power = 0.0;
  for (const PunctualLight& light : lighting.source->lights) {
    powers.push_back(punctual_power(light, radius));
    if (powers.back() > 0) lighting.punctual_power += powers.back();
  }
  lighting.punctual_cdf = padded_cdf(Distribution1D(powers));
}

// The refresh_*_from_source functions' checks: as many records in the source as in the lighting
// scene, and every listed index within them.
void check_source_indices(const char* function, const char* what, size_t source_count, size_t lighting_count,
                          const std::vector<uint32_t>& indices) {
  if (source_count != lighting_count)
    throw std::invalid_argument(std::string(function) + ": the source has " + std::to_string(source_count) + " " + what +
                                "s, the lighting scene " + std::to_string(lighting_count));
  for (uint32_t i : indices)
    if (i >= source_count)
      throw std::out_of_range(std::string(function) + ": " + what + " " + std::to_string(i) + " of " + std::to_string(source_count));
}

// Edits copy the source Scene (copy on write): the CPU reference, other LightingScenes and the
// offline stage may share it, and it is immutable for them.
Scene& writable_source(LightingScene& lighting) {
  auto copy = std::make_shared<Scene>(*lighting.source);
  Scene& scene = *copy;
  lighting.source = std::move(copy);
  return scene;
}

}  // namespace

float scene_radius(const LightingScene& lighting) {
  if (lighting.triangles.empty()) return 1.0f;
  return std::max(0.5f * length(lighting.bounds_hi - lighting.bounds_lo), 1e-6f);
}

LightingScene build_lighting_scene(std::shared_ptr<const Scene> source, Bvh4 bvh) {
  const Scene& scene = *source;
  const size_t triangle_count = scene.triangle_count();
  check_bvh_references(bvh, triangle_count);
  LightingScene lighting;
  lighting.bvh = std::move(bvh);
  lighting.source = std::move(source);

  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const Vec3& p : scene.positions) lo = min(lo, p), hi = max(hi, p);
  if (triangle_count > 0) {
    lighting.bounds_lo = lo, lighting.bounds_hi = hi;
    lighting.extent = std::max(max_component(hi - lo), 1e-30f);
  }

  lighting.triangles.resize(triangle_count);
  for (size_t t = 0; t < triangle_count; ++t) {
    const Vec3* p = &scene.positions[t * 3];
    const Vec3* n = &scene.normals[t * 3];
    GpuTriangle& g = lighting.triangles[t];
    g.p0_material = Vec4(p[0], uintBitsToFloat(scene.triangle_material[t]));
    g.p1_emitter = Vec4(p[1], 0.0f);  // build_emitter_distribution
    g.p2_instance = Vec4(p[2], uintBitsToFloat(scene.triangle_instance.empty() ? 0u : scene.triangle_instance[t]));
    g.n0 = Vec4(n[0], 0.0f), g.n1 = Vec4(n[1], 0.0f), g.n2 = Vec4(n[2], 0.0f);
  }
  lighting.textured = !scene.vertex_color.empty();
  for (const Material& m : scene.materials) {
    lighting.materials.push_back(material_record(m));
    lighting.textured = lighting.textured || varies_per_point(m);
  }
  for (const PunctualLight& light : scene.lights) lighting.punctual_lights.push_back(punctual_record(light));
  build_emitter_distribution(lighting);
  build_punctual_distribution(lighting);

  lighting.sky = scene.sky.constant;
  if (scene.sky.has_environment()) lighting.environment = EnvironmentSampler(scene.sky.environment);
  lay_out_light_layers(lighting, kDefaultLightLayerLimit);
  return lighting;
}

void lay_out_light_layers(LightingScene& lighting, uint32_t limit) {
  if (limit == 0) throw std::invalid_argument("lay_out_light_layers: the limit must be at least 1");
  lighting.punctual_light_layers = punctual_light_layer_count(lighting.punctual_count(), limit);
  const uint32_t first_material_layer = 1 + lighting.punctual_light_layers;
  uint32_t emissive = 0;
  for (const GpuMaterial& m : lighting.materials) emissive += m.emission.x > 0 || m.emission.y > 0 || m.emission.z > 0;
  const uint32_t material_layers = std::min(emissive, limit);
  const uint32_t later = first_material_layer + material_layers;  // materials made emissive by an edit
  lighting.light_layer_count = later + 1;
  lighting.material_light_layers.assign(lighting.materials.size(), later);
  uint32_t k = 0;
  for (size_t i = 0; i < lighting.materials.size(); ++i) {
    const GpuMaterial& m = lighting.materials[i];
    if (m.emission.x > 0 || m.emission.y > 0 || m.emission.z > 0)
      lighting.material_light_layers[i] = first_material_layer + std::min(k++, material_layers - 1);
    lighting.materials[i].emission.w = float(lighting.material_light_layers[i]);
  }
}

void set_geometry(LightingScene& lighting, std::shared_ptr<const Scene> edited) {
  if (!edited || edited->triangle_count() != lighting.triangles.size() ||
      edited->positions.size() != edited->triangle_count() * 3)
    throw std::invalid_argument("set_geometry: the edited scene has " +
                                std::to_string(edited ? edited->triangle_count() : 0) + " triangles, not " +
                                std::to_string(lighting.triangles.size()));
  Bvh4 bvh = lighting.bvh;
  // The boxes fit the source's positions: the leaves of triangles that did not move keep theirs.
  const std::vector<Vec3>* fitted_to =
      lighting.source && lighting.source->positions.size() == edited->positions.size() ? &lighting.source->positions : nullptr;
  if (!bvh.nodes.empty()) refit_bvh4(bvh, edited->positions, fitted_to);
  // The layers stay as they were laid out (a layer's sums are its light's).
  const uint32_t punctual_layers = lighting.punctual_light_layers, layer_count = lighting.light_layer_count;
  std::vector<uint32_t> material_layers = std::move(lighting.material_light_layers);
  lighting = build_lighting_scene(std::move(edited), std::move(bvh));
  lighting.punctual_light_layers = punctual_layers, lighting.light_layer_count = layer_count;
  lighting.material_light_layers = std::move(material_layers);
  for (size_t i = 0; i < lighting.materials.size(); ++i) lighting.materials[i].emission.w = float(lighting.material_light_layers[i]);
}

void set_material(LightingScene& lighting, uint32_t index, const Material& material) {
  if (index >= lighting.materials.size())
    throw std::out_of_range("set_material: material " + std::to_string(index) + " of " +
                            std::to_string(lighting.materials.size()));
  writable_source(lighting).materials[index] = material;
  refresh_materials_from_source(lighting, {index});
}

void refresh_lights_from_source(LightingScene& lighting, const std::vector<uint32_t>& lights, bool sky) {
  const Scene& scene = *lighting.source;
  check_source_indices("refresh_lights_from_source", "light", scene.lights.size(), lighting.punctual_lights.size(), lights);
  for (uint32_t l : lights) lighting.punctual_lights[l] = punctual_record(scene.lights[l]);
  if (!lights.empty()) build_punctual_distribution(lighting);
  if (sky) {
    lighting.sky = scene.sky.constant;
    lighting.environment = scene.sky.has_environment() ? EnvironmentSampler(scene.sky.environment) : EnvironmentSampler{};
  }
}

void refresh_materials_from_source(LightingScene& lighting, const std::vector<uint32_t>& materials) {
  const Scene& scene = *lighting.source;
  check_source_indices("refresh_materials_from_source", "material", scene.materials.size(), lighting.materials.size(), materials);
  if (materials.empty()) return;
  for (uint32_t m : materials) {
    lighting.materials[m] = material_record(scene.materials[m]);
    lighting.materials[m].emission.w = float(lighting.material_light_layers[m]);  // its layer stays
  }
  lighting.textured = !scene.vertex_color.empty();
  for (const Material& m : scene.materials) lighting.textured = lighting.textured || varies_per_point(m);
  if (!refresh_edited_emitters(lighting, materials)) build_emitter_distribution(lighting);
}

MovedTrianglesRefresh refresh_moved_triangles_from_source(LightingScene& lighting, const Bvh4Links& links,
                                                          const std::vector<uint32_t>& moved,
                                                          const std::vector<Vec3>& moved_before, const WorldBox& bounds) {
  const Scene& scene = *lighting.source;
  if (scene.triangle_count() != lighting.triangles.size() || scene.positions.size() != scene.triangle_count() * 3)
    throw std::invalid_argument("refresh_moved_triangles_from_source: the source has " + std::to_string(scene.triangle_count()) +
                                " triangles, the lighting scene " + std::to_string(lighting.triangles.size()));
  MovedTrianglesRefresh out;
  if (!lighting.bvh.nodes.empty()) out.bvh_nodes = refit_bvh4_moved(lighting.bvh, links, scene.positions, moved, moved_before);
  bool& emitter_moved = out.emitters_changed;
  for (uint32_t t : moved) {
    const Vec3* p = &scene.positions[size_t(t) * 3];
    const Vec3* n = &scene.normals[size_t(t) * 3];
    GpuTriangle& g = lighting.triangles[t];
    emitter_moved = emitter_moved || g.p1_emitter.w != 0.0f || is_emissive(scene, t);
    g.p0_material = Vec4(p[0], g.p0_material.w);
    g.p1_emitter = Vec4(p[1], g.p1_emitter.w);
    g.p2_instance = Vec4(p[2], g.p2_instance.w);
    g.n0 = Vec4(n[0], 0.0f), g.n1 = Vec4(n[1], 0.0f), g.n2 = Vec4(n[2], 0.0f);
  }
  if (!lighting.triangles.empty()) {
    lighting.bounds_lo = bounds.lo, lighting.bounds_hi = bounds.hi;
    lighting.extent = std::max(max_component(bounds.hi - bounds.lo), 1e-30f);
  }
  if (emitter_moved && !refresh_emitter_powers(lighting, moved)) build_emitter_distribution(lighting);  // areas follow the moved emitters
  build_punctual_distribution(lighting);                      // directional powers follow the bounds
  for (size_t l = 0; l < scene.lights.size() && l < lighting.punctual_lights.size(); ++l)
    lighting.punctual_lights[l] = punctual_record(scene.lights[l]);
  return out;
}

void set_punctual_light(LightingScene& lighting, uint32_t index, const PunctualLight& light) {
  if (index >= lighting.punctual_lights.size())
    throw std::out_of_range("set_punctual_light: light " + std::to_string(index) + " of " +
                            std::to_string(lighting.punctual_lights.size()));
  writable_source(lighting).lights[index] = light;
  lighting.punctual_lights[index] = punctual_record(light);
  build_punctual_distribution(lighting);
}

}  // namespace exitance
