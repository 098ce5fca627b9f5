// The texture-space filter's neighbour weight (bake --denoise; runtime/bundle/indirect_denoise.h),
// one text for the host and a device kernel: a texel's indirect light is averaged with atlas
// neighbours that lie on the same surface, so the filter never crosses a chart border onto another
// surface (atlas neighbours that are far apart in the world), a crease (normals apart) or a step
// (the neighbour off the texel's plane). Inside a surface the weight is a Gaussian of the atlas
// offset. Indirect light varies slowly across a surface, so averaging K texels divides its noise
// variance by up to K at the price of a bias where it does vary within the window (measured:
// docs/features.md, bench/results/denoise.md).
#ifndef EXITANCE_COMMON_TEXTURE_SPACE_FILTER_H
#define EXITANCE_COMMON_TEXTURE_SPACE_FILTER_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

// The largest window radius in texels (a (2 r + 1)^2 window): bake, exitance-relight and the runtime
// accept 1 to this.
const int kFilterMaxRadius = 16;

// Normals of the same surface: cosine of the angle between them at least this (about 18 degrees).
const float kFilterNormalCosine = 0.95f;
// The neighbour's distance from the texel's plane, in the texel's world size, at most this.
const float kFilterPlaneTexels = 0.5f;
// The neighbour's world distance at most this many times its atlas distance in world texel sizes
// (charts are laid out at one density: a neighbour on the same surface is about as far in the world
// as in the atlas; one across a chart border is anywhere).
const float kFilterWorldStretch = 1.5f;

// Weight of the neighbour at atlas offset (dx, dy) of a texel at `position` with unit geometric
// normal `normal` and world texel size `texel_size`, for a window of `radius` texels: 0 off the
// texel's surface, else exp(-(dx^2 + dy^2) / (2 sigma^2)) with sigma = radius / 2.
EXITANCE_FN float texture_space_filter_weight(vec3 position, vec3 normal, float texel_size, vec3 neighbour_position,
                                              vec3 neighbour_normal, int dx, int dy, int radius) {
  if (dot(normal, neighbour_normal) < kFilterNormalCosine) return 0.0f;
  vec3 offset = neighbour_position - position;
  if (abs(dot(normal, offset)) > kFilterPlaneTexels * texel_size) return 0.0f;
  float atlas_distance = sqrt(float(dx * dx + dy * dy));
  if (length(offset) > kFilterWorldStretch * (atlas_distance + 1.0f) * texel_size) return 0.0f;
  float sigma = 0.5f * float(radius);
  return exp(-float(dx * dx + dy * dy) / (2.0f * sigma * sigma));
}

// Standard deviations of two texels' difference at which the range weight below is exp(-1/2).
const float kFilterRangeSigmas = 2.0f;

// The value's edge stop: neighbours whose indirect light differs from the texel's by more than their
// noise explains weigh less, exp(-|x_j - x_i|^2 / (2 k^2 (V_i + V_j))) with k kFilterRangeSigmas,
// squares and variances of the mean summed over the channels. Geometry cannot see an occluder
// resting on a surface (a box on a floor): the floor under it is black, its neighbours lit, all on
// one plane; their difference is many standard errors, so no light leaks in. Two exact values
// (no variance) mix only if equal.
// Beyond this exponent the weight is 0: exp(-80) = 1.8e-35 is still a normal float, so the host and a
// device that flushes denormals to zero (lavapipe may) take the same neighbours.
const float kFilterRangeCutoff = 80.0f;

EXITANCE_FN float texture_space_filter_range_weight(float difference_squared, float variance_sum) {
  if (!(variance_sum > 0.0f)) return difference_squared > 0.0f ? 0.0f : 1.0f;
  float exponent = difference_squared / (2.0f * kFilterRangeSigmas * kFilterRangeSigmas * variance_sum);
  if (exponent > kFilterRangeCutoff) return 0.0f;
  return exp(-exponent);
}

EXITANCE_NAMESPACE_END
#endif
