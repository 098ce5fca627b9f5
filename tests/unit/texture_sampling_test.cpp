// The texture sampling shared by the CPU reference and the kernels (exitance/common/texture_sampling.h)
// against hand-computed values: wrap modes on negative and large indices, the bilinear footprint and
// weights, huge and non-finite coordinates, KHR_texture_transform.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/common/texture_sampling.h"
#include "exitance/runtime/material_eval.h"

namespace exitance {
namespace {

TEST(TextureSampling, FloorModIsNonNegative) {
  EXPECT_EQ(floor_mod(5, 4), 1);
  EXPECT_EQ(floor_mod(-1, 4), 3);
  EXPECT_EQ(floor_mod(-4, 4), 0);
  EXPECT_EQ(floor_mod(-9, 4), 3);
}

TEST(TextureSampling, WrapModes) {
  EXPECT_EQ(wrap_texel_index(-1, 4, kWrapRepeat), 3);
  EXPECT_EQ(wrap_texel_index(9, 4, kWrapRepeat), 1);
  EXPECT_EQ(wrap_texel_index(-1, 4, kWrapClampToEdge), 0);
  EXPECT_EQ(wrap_texel_index(5, 4, kWrapClampToEdge), 3);
  // Mirrored, period 8: 0 1 2 3 3 2 1 0 | 0 1 ...
  EXPECT_EQ(wrap_texel_index(4, 4, kWrapMirroredRepeat), 3);
  EXPECT_EQ(wrap_texel_index(5, 4, kWrapMirroredRepeat), 2);
  EXPECT_EQ(wrap_texel_index(8, 4, kWrapMirroredRepeat), 0);
  EXPECT_EQ(wrap_texel_index(-1, 4, kWrapMirroredRepeat), 0);
  EXPECT_EQ(wrap_texel_index(-5, 4, kWrapMirroredRepeat), 3);
}

TEST(TextureSampling, BilinearFootprint) {
  // 4 x 2 texels: x = 0.25 * 4 - 0.5 = 0.5, y = 0.5 * 2 - 0.5 = 0.5.
  BilinearTaps t = bilinear_taps({0.25f, 0.5f}, 4, 2, kWrapRepeat, kWrapRepeat);
  EXPECT_EQ(t.x0, 0);
  EXPECT_EQ(t.x1, 1);
  EXPECT_EQ(t.y0, 0);
  EXPECT_EQ(t.y1, 1);
  EXPECT_FLOAT_EQ(t.tx, 0.5f);
  EXPECT_FLOAT_EQ(t.ty, 0.5f);
  // At the corner, half a texel outside: repeat reads the last column, clamp the first twice.
  t = bilinear_taps({0.0f, 0.0f}, 4, 4, kWrapRepeat, kWrapClampToEdge);
  EXPECT_EQ(t.x0, 3);
  EXPECT_EQ(t.x1, 0);
  EXPECT_EQ(t.y0, 0);
  EXPECT_EQ(t.y1, 0);
  EXPECT_FLOAT_EQ(t.tx, 0.5f);
  // u = -1.875: x = -8 exactly, texel 0 with weight 1.
  t = bilinear_taps({-1.875f, 0.375f}, 4, 4, kWrapRepeat, kWrapRepeat);
  EXPECT_EQ(t.x0, 0);
  EXPECT_EQ(t.x1, 1);
  EXPECT_EQ(t.tx, 0.0f);
  EXPECT_EQ(t.y0, 1);
  EXPECT_EQ(t.ty, 0.0f);
}

TEST(TextureSampling, HugeAndNonFiniteCoordinates) {
  EXPECT_EQ(reduced_texture_coordinate(131072.25f), 0.25f);
  EXPECT_EQ(reduced_texture_coordinate(-131072.25f), -0.25f);
  EXPECT_EQ(reduced_texture_coordinate(0.75f), 0.75f);
  EXPECT_EQ(reduced_texture_coordinate(3.0e9f), std::fmod(3.0e9f, 131072.0f));
  const BilinearTaps far = bilinear_taps({131072.25f, 0.0f}, 4, 4, kWrapRepeat, kWrapRepeat);
  const BilinearTaps near = bilinear_taps({0.25f, 0.0f}, 4, 4, kWrapRepeat, kWrapRepeat);
  EXPECT_EQ(far.x0, near.x0);
  EXPECT_EQ(far.x1, near.x1);
  EXPECT_EQ(far.tx, near.tx);
  const BilinearTaps nan = bilinear_taps({NAN, 0.5f}, 4, 4, kWrapRepeat, kWrapRepeat);
  EXPECT_EQ(nan.x0 | nan.x1 | nan.y0 | nan.y1, 0);
  EXPECT_EQ(nan.tx + nan.ty, 0.0f);
}

TEST(TextureSampling, Transform) {
  const Vec2 same = transform_texture_coordinate({0.3f, 0.7f}, {0, 0}, {1, 1}, 0.0f);
  EXPECT_EQ(same.x, 0.3f);
  EXPECT_EQ(same.y, 0.7f);
  // Scale (2, 3), rotation pi/2 ([0 1; -1 0]), offset (0.5, 0.25): (1, 0) -> (2, 0) -> (0, -2) -> (0.5, -1.75).
  const Vec2 t = transform_texture_coordinate({1.0f, 0.0f}, {0.5f, 0.25f}, {2.0f, 3.0f}, float(M_PI / 2));
  EXPECT_NEAR(t.x, 0.5f, 1e-6f);
  EXPECT_NEAR(t.y, -1.75f, 1e-6f);
}

TEST(TextureSampling, CpuLookupUsesTheSharedFootprint) {
  Texture texture;
  texture.width = 2, texture.height = 1;
  texture.rgb = {0, 0, 0, 1, 2, 4};
  texture.alpha = {0, 1};
  texture.wrap_s = texture.wrap_t = Texture::Wrap::ClampToEdge;
  // u = 0.375: x = 0.25, a quarter of the way from texel 0 to texel 1.
  const Vec3 c = sample_texture(texture, {0.375f, 0.5f});
  EXPECT_FLOAT_EQ(c.x, 0.25f);
  EXPECT_FLOAT_EQ(c.y, 0.5f);
  EXPECT_FLOAT_EQ(c.z, 1.0f);
  EXPECT_FLOAT_EQ(sample_texture_alpha(texture, {0.375f, 0.5f}), 0.25f);
  EXPECT_FLOAT_EQ(sample_texture_alpha(texture, {0.1f, 0.5f}), 0.0f);
}

}  // namespace
}  // namespace exitance
