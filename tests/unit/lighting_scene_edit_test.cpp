// Runtime edits of a LightingScene (set_material, set_punctual_light) must leave it exactly as
// build_lighting_scene would build it from the edited Scene: records (the materials' power per
// area, the triangles' emitter flags), CDFs; except the light layers, which stay as laid out when the scene was built (a layer's sums are its
// light's), where a rebuild lays them out for the edited emitters.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <stdexcept>

#include "exitance/common/vector_functions.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "support/analytic_scenes.h"

namespace exitance {
namespace {

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expect_same(const LightingScene& edited, LightingScene rebuilt) {
  // The rebuilt scene with the edited one's light layers (emission.w), as its layout kept them.
  ASSERT_EQ(edited.materials.size(), rebuilt.materials.size());
  for (size_t i = 0; i < rebuilt.materials.size(); ++i) rebuilt.materials[i].emission.w = edited.materials[i].emission.w;
  EXPECT_TRUE(same_bytes(edited.triangles, rebuilt.triangles));
  EXPECT_TRUE(same_bytes(edited.materials, rebuilt.materials));
  EXPECT_TRUE(same_bytes(edited.punctual_lights, rebuilt.punctual_lights));
  EXPECT_EQ(edited.emitter_triangles, rebuilt.emitter_triangles);
  EXPECT_EQ(edited.emitter_cdf, rebuilt.emitter_cdf);
  EXPECT_EQ(edited.emitter_areas, rebuilt.emitter_areas);
  EXPECT_EQ(edited.emitter_inverse_power, rebuilt.emitter_inverse_power);
  EXPECT_EQ(edited.punctual_cdf, rebuilt.punctual_cdf);
  EXPECT_EQ(edited.textured, rebuilt.textured);
}

// Two emitters and a receiver: editing the receiver into a third emitter grows the emitter list and
// changes every emitter's area pdf; editing an emitter black shrinks it.
Scene three_quads() {
  Scene scene;
  testing::add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, testing::add_material(scene, {0.5f, 0.5f, 0.5f}));
  testing::add_quad(scene, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, testing::add_material(scene, {0, 0, 0}, {2, 1, 0.5f}));
  testing::add_quad(scene, {0, 2, 0}, {2, 0, 0}, {0, 0, 2}, testing::add_material(scene, {0.2f, 0.2f, 0.2f}, {1, 1, 1}, true));
  PunctualLight point;
  point.position = {0.5f, 3, 0.5f};
  scene.lights.push_back(point);
  PunctualLight sun;
  sun.type = PunctualLight::Type::Directional;
  sun.intensity = {2, 2, 2};
  scene.lights.push_back(sun);
  return scene;
}

TEST(LightingSceneEdit, SetMaterialMatchesARebuild) {
  const Scene scene = three_quads();
  LightingScene edited = *make_lighting_scene(scene);
  const std::shared_ptr<const Scene> original_source = edited.source;
  Scene expected = scene;
  for (auto [index, emission] : {std::pair{0u, Vec3{0.3f, 0.3f, 0.3f}}, std::pair{1u, Vec3{0, 0, 0}}, std::pair{2u, Vec3{5, 4, 3}}}) {
    Material m = expected.materials[index];
    m.emission = emission;
    m.base_color = {0.9f, 0.1f, 0.4f};
    set_material(edited, index, m);
    expected.materials[index] = m;
    expect_same(edited, build_lighting_scene(std::make_shared<const Scene>(expected), edited.bvh));
    EXPECT_EQ(edited.source->materials[index].base_color.x, 0.9f);
  }
  EXPECT_EQ(edited.emitter_count(), 4u);  // the receiver's two triangles and the large quad's
  // Laid out when built (materials 1 and 2 emissive): sky, 2 punctual, 2 emissive, 1 for later
  // emitters, which material 0 (made emissive above) uses; material 1 (made black) keeps its layer.
  EXPECT_EQ(edited.light_layer_count, 6u);
  EXPECT_EQ(edited.material_light_layers, (std::vector<uint32_t>{5, 3, 4}));
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(edited.materials[i].emission.w, float(edited.material_light_layers[i]));
  EXPECT_EQ(original_source->materials[1].emission.x, 2.0f) << "the shared source Scene must not change";
  EXPECT_THROW(set_material(edited, 3, Material{}), std::out_of_range);
}

// Emission edits that keep every emitter emitting (brighter, dimmer, another colour) keep the list:
// the distribution is derived from the emitters alone (their kept areas), still equal to a rebuild.
TEST(LightingSceneEdit, EmissionEditsKeepingTheEmittersMatchARebuild) {
  const Scene scene = three_quads();
  LightingScene edited = *make_lighting_scene(scene);
  const std::vector<uint32_t> emitters = edited.emitter_triangles;
  Scene expected = scene;
  for (auto [index, emission] : {std::pair{1u, Vec3{6, 3, 1.5f}}, std::pair{2u, Vec3{0.1f, 0.2f, 0.05f}}, std::pair{1u, Vec3{0, 0, 1e-3f}}}) {
    Material m = expected.materials[index];
    m.emission = emission;
    set_material(edited, index, m);
    expected.materials[index] = m;
    expect_same(edited, build_lighting_scene(std::make_shared<const Scene>(expected), edited.bvh));
    EXPECT_EQ(edited.emitter_triangles, emitters);
  }
}

// The area density NEE and the MIS weight at a hit read (a record's power per area x the total's
// inverse) is the density NEE samples with: the emitter's CDF cell over its area. Closed form on
// three_quads: an emissive quad of area 1 (luminance L1, one side) and one of area 4 (luminance 1,
// both sides: x2); the receiver's triangles 0.
TEST(LightingSceneEdit, TheEmittersAreaPdfIsTheirPowerPerAreaOverTheTotal) {
  const LightingScene lighting = *make_lighting_scene(three_quads());
  ASSERT_EQ(lighting.emitter_count(), 4u);
  const double l1 = luminance(Vec3{2, 1, 0.5f}), total = l1 * 1 + 2.0 * 4;
  EXPECT_NEAR(lighting.emitter_inverse_power, 1 / total, 1e-6 / total);
  for (uint32_t i = 0; i < lighting.emitter_count(); ++i) {
    const uint32_t t = lighting.emitter_triangles[i];
    const vec3 p0 = scene_triangle_vertex(lighting, t, 0), p1 = scene_triangle_vertex(lighting, t, 1), p2 = scene_triangle_vertex(lighting, t, 2);
    const double area = 0.5 * double(length(cross(p1 - p0, p2 - p0)));
    const double sampled = (lighting.emitter_cdf[i + 1] - lighting.emitter_cdf[i]) / area;  // what NEE picks a point with
    const double closed_form = (t < 4 ? l1 : 2.0) / total;
    EXPECT_NEAR(scene_triangle_area_pdf(lighting, t), sampled, 1e-6 * sampled) << "emitter " << i;
    EXPECT_NEAR(scene_triangle_area_pdf(lighting, t), closed_form, 1e-6 * closed_form) << "emitter " << i;
  }
  EXPECT_EQ(scene_triangle_area_pdf(lighting, 0), 0.0f) << "the receiver";
  EXPECT_EQ(scene_triangle_area_pdf(lighting, 1), 0.0f) << "the receiver";
}

TEST(LightingSceneEdit, SetPunctualLightMatchesARebuild) {
  const Scene scene = three_quads();
  LightingScene edited = *make_lighting_scene(scene);
  Scene expected = scene;
  PunctualLight spot;
  spot.type = PunctualLight::Type::Spot;
  spot.position = {0.5f, 1.5f, 0.5f};
  spot.direction = {0, -1, 0};
  spot.intensity = {30, 10, 10};
  spot.cos_inner = 0.9f;
  spot.cos_outer = 0.8f;
  set_punctual_light(edited, 0, spot);
  expected.lights[0] = spot;
  PunctualLight sun = expected.lights[1];
  sun.intensity = {0, 0, 0};
  set_punctual_light(edited, 1, sun);
  expected.lights[1] = sun;
  expect_same(edited, build_lighting_scene(std::make_shared<const Scene>(expected), edited.bvh));
  EXPECT_EQ(edited.punctual_cdf[1], 1.0) << "the black sun is never chosen";
  EXPECT_THROW(set_punctual_light(edited, 2, spot), std::out_of_range);
}

}  // namespace
}  // namespace exitance
