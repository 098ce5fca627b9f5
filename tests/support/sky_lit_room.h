// A room lit only through a door gap by the sky and a sun (the light-subpath tests of sky and
// directional starts): the unit box's walls and ceiling, inward and double sided (light outside
// bounces off their outer sides too), on a 4 m x 4 m ground, the front wall (z = 1) split by a
// 10 cm gap at x in [0.45, 0.55], its whole height. The sun travels down and toward -z, so it lights
// the ground in front of the gap and a strip of the floor through it.
#pragma once
#include "support/atlas_box.h"
#include "support/test_scenes.h"

namespace exitance::testing {

// `environment`: the sky an 32 x 16 image (0.2, with a patch of 20 low over the horizon in front of
// the gap) instead of the constant 0.5.
inline AtlasScene sky_lit_room(bool environment, float density) {
  AtlasScene a;
  Scene& scene = a.scene;
  const Vec3 ex{1, 0, 0}, ey{0, 1, 0}, ez{0, 0, 1};
  const uint32_t ground = add_material(scene, {0.5f, 0.5f, 0.5f});
  const uint32_t wall = add_material(scene, {0.6f, 0.6f, 0.6f}, {0, 0, 0}, true);
  auto quad = [&](const char* name, Vec3 c0, Vec3 u, Vec3 v, uint32_t material) {
    add_quad(scene, c0, u, v, material);
    scene.instances.back().name = name;
  };
  quad("ground", {-1.5f, 0, -1.5f}, ez * 4.0f, ex * 4.0f, ground);
  quad("ceiling", {0, 1, 0}, ex, ez, wall);
  quad("back", {0, 0, 0}, ex, ey, wall);
  quad("left", {0, 0, 0}, ey, ez, wall);
  quad("right", {1, 0, 0}, ez, ey, wall);
  quad("front_left", {0, 0, 1}, ey, ex * 0.45f, wall);
  quad("front_right", {0.55f, 0, 1}, ey, ex * 0.45f, wall);
  PunctualLight sun;
  sun.type = PunctualLight::Type::Directional;
  sun.name = "sun";
  sun.direction = normalize(Vec3{0.15f, -0.8f, -0.5f});
  sun.intensity = {3.0f, 2.8f, 2.5f};
  scene.lights.push_back(sun);
  if (environment) {
    Texture& sky = scene.sky.environment;
    sky.width = 32;
    sky.height = 16;
    sky.rgb.assign(size_t(sky.width * sky.height * 3), 0.2f);
    // u = 0.5 + atan2(x, -z) / 2 pi: +z is column 0 (and 31); rows 5..7 are 56-79 degrees from +Y.
    for (int row = 5; row <= 7; ++row)
      for (int column : {0, 1, 30, 31})
        for (int c = 0; c < 3; ++c) sky.rgb[size_t((row * sky.width + column) * 3 + c)] = 20.0f;
  } else {
    scene.sky.constant = {0.5f, 0.55f, 0.6f};
  }
  AtlasSettings atlas;
  atlas.texel_density = density;
  Diagnostics diagnostics;
  const AtlasLayout layout = layout_lightmap_atlas(scene, atlas, "sky_lit_room", diagnostics);
  a.gbuffer = rasterize_texel_gbuffer(scene, layout, "sky_lit_room", diagnostics);
  return a;
}

}  // namespace exitance::testing
