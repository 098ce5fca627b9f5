// An analytic image sky (issue 13): an equirect map with an upper half `up`, a lower half `down` and
// a bright block in the upper half, over black quads tilted by known angles, where E/pi has a closed
// form. Shared by the CPU/Vulkan lightmap and probe cross-checks.
#pragma once
#include <cmath>
#include <vector>

#include "exitance/common/sampling.h"
#include "support/analytic_scenes.h"

namespace exitance::testing {

struct ImageSkyScene {
  Scene scene;
  TexelGBuffer gbuffer;
  std::vector<Vec3> exact;          // E/pi per texel
  std::vector<size_t> group_begin;  // texels of one quad (one normal) are consecutive: group g starts here
  Vec3 probe_c00;                   // SH coefficient c00 of the whole sky seen from a free point
};

struct SkyBlock {
  int row0, row1, column0, column1;  // [row0, row1) x [column0, column1) of the image
};

// The map: width x height texels, row 0 = +Y (environment_map.h).
inline Texture two_valued_sky(int width, int height, Vec3 up, Vec3 down, Vec3 block_radiance, SkyBlock block) {
  Texture t;
  t.width = width;
  t.height = height;
  t.rgb.resize(size_t(width) * size_t(height) * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const bool in_block = y >= block.row0 && y < block.row1 && x >= block.column0 && x < block.column1;
      const Vec3 c = in_block ? block_radiance : (2 * y < height ? up : down);
      const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
      t.rgb[i] = c.x, t.rgb[i + 1] = c.y, t.rgb[i + 2] = c.z;
    }
  return t;
}

// Texels on black single-sided quads with normals n = (sin a, cos a, 0), far apart along z (each
// quad sees the others under ~1e-6 sr). The upper half contributes up (1 + cos a) / 2 and the lower
// down (1 - cos a) / 2; the block, in theta [t0, t1] (< pi/2) and phi [p0, p1] inside (0, pi) (so it
// is wholly above every tilted quad), adds (block - up)/pi * integral of n.d over it:
//   n.d = sin a sin(theta) sin(phi) + cos a cos(theta), d omega = sin(theta) d theta d phi.
inline ImageSkyScene image_sky_over_tilted_quads() {
  ImageSkyScene s;
  const int width = 64, height = 32;
  const Vec3 up{0.4f, 0.6f, 1.0f}, down{0.3f, 0.2f, 0.1f}, bright{50.0f, 40.0f, 30.0f};
  const SkyBlock block{4, 8, 40, 48};  // theta [22.5, 45] degrees, phi [45, 90] degrees
  s.scene.sky.environment = two_valued_sky(width, height, up, down, bright, block);
  const double t0 = kPi * block.row0 / height, t1 = kPi * block.row1 / height;
  const double p0 = (double(block.column0) / width - 0.5) * 2 * kPi, p1 = (double(block.column1) / width - 0.5) * 2 * kPi;
  const double sin2_integral = (t1 / 2 - std::sin(2 * t1) / 4) - (t0 / 2 - std::sin(2 * t0) / 4);  // of sin^2
  const double cos_sin_integral = (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0)) / 2;
  const uint32_t black = add_material(s.scene, {0, 0, 0});
  const double tilts_degrees[] = {0, 60, 90, 180};
  for (int q = 0; q < 4; ++q) {
    const double a = tilts_degrees[q] * kPi / 180;
    const Vec3 n{float(std::sin(a)), float(std::cos(a)), 0.0f};
    const Vec3 tangent{float(std::cos(a)), float(-std::sin(a)), 0.0f}, bitangent{0, 0, -1};  // cross = n
    const Vec3 corner = Vec3{0, 0, 1000.0f * float(q)} - tangent * 0.5f - bitangent * 0.5f;
    add_quad(s.scene, corner, tangent, bitangent, black);
    // The block counts only when it lies wholly above the quad (a < 90 degrees here: checked above).
    const double block_term = q == 3 ? 0.0
                                     : (std::sin(a) * sin2_integral * (std::cos(p0) - std::cos(p1)) +
                                        std::cos(a) * cos_sin_integral * (p1 - p0)) / kPi;
    Vec3 e;
    for (int c = 0; c < 3; ++c)
      e[c] = float(up[c] * (1 + std::cos(a)) / 2 + down[c] * (1 - std::cos(a)) / 2 + (bright[c] - up[c]) * block_term);
    s.group_begin.push_back(s.gbuffer.texels.size());
    for (Vec2 p : grid_points(4, 0.1f)) {
      s.gbuffer.texels.push_back(texel_at(corner + tangent * p.x + bitangent * p.y, n));
      s.exact.push_back(e);
    }
  }
  // c00 = Y00 * integral of L over the sphere, Y00 = 1 / (2 sqrt(pi)).
  const double block_solid_angle = (std::cos(t0) - std::cos(t1)) * (p1 - p0);
  for (int c = 0; c < 3; ++c)
    s.probe_c00[c] = float((2 * kPi * (up[c] + down[c]) + (bright[c] - up[c]) * block_solid_angle) / (2 * std::sqrt(kPi)));
  return s;
}

}  // namespace exitance::testing
