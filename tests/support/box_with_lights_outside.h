// A closed box lit inside by a small lamp and a point light, with far brighter lights outside: the
// default next-event sampling by power sends 99 % of its shadow rays to lights that never arrive, so
// emitter guiding's learned distributions pay (emitter_guided_path_test.cpp, the Vulkan crosscheck).
#pragma once
#include <cmath>

#include "support/atlas_box.h"

namespace exitance::testing {

// The unit box (albedo 0.5) lit inside by a 20 cm lamp under the ceiling (radiance 50) and a point
// light (intensity 0.5), with an emitter 100x the lamp's power and a point light 100x brighter
// outside above the closed ceiling: the default sampling by power sends 99 % of its shadow rays to
// the lights outside, which never arrive.
inline AtlasScene box_with_lights_outside() {
  const Vec3 black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  AtlasScene box = atlas_box(0.5f, emission, 8, 0.2f, {50, 50, 50});
  // Outside: 1 m^2 facing down onto the ceiling's outer side at y = 1.5 (power 100x the lamp's).
  add_quad(box.scene, {0, 1.5f, 0}, {1, 0, 0}, {0, 0, 1}, add_material(box.scene, {0, 0, 0}, {200, 200, 200}));
  box.scene.instances.back().name = "outside_emitter";
  PunctualLight inside;
  inside.name = "inside";
  inside.position = {0.3f, 0.5f, 0.6f};
  inside.intensity = {0.5f, 0.5f, 0.5f};
  PunctualLight outside = inside;
  outside.name = "outside";
  outside.position = {0.5f, 2.0f, 0.5f};
  outside.intensity = {50, 50, 50};
  box.scene.lights = {outside, inside};
  return box;
}

// The same box with a spot light inside too, tilted, its cone partly on the walls (light subpaths'
// tests: every kind of start at once).
inline AtlasScene box_with_lights_outside_and_a_spot() {
  AtlasScene box = box_with_lights_outside();
  PunctualLight spot;
  spot.type = PunctualLight::Type::Spot;
  spot.name = "spot";
  spot.position = {0.7f, 0.8f, 0.3f};
  spot.direction = normalize(Vec3{-0.5f, -1.0f, 0.4f});
  spot.intensity = {1.0f, 0.8f, 0.6f};
  spot.cos_inner = std::cos(0.3f);
  spot.cos_outer = std::cos(0.6f);
  box.scene.lights.push_back(spot);
  return box;
}

}  // namespace exitance::testing
