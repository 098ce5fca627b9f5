// The texture-space filter's neighbour weight (bake --denoise; runtime/bundle/indirect_denoise.h),
// one text for the host and a device kernel: a texel's indirect light is fitted over atlas
// neighbours that lie on the same surface, so the filter never crosses a chart border onto another
// surface (atlas neighbours that are far apart in the world), a crease (normals apart) or a step
// (the neighbour off the texel's plane). Inside a surface the weight is a Gaussian of the atlas
// offset. Indirect light varies slowly across a surface, so fitting K texels divides its noise
// variance by nearly K at the price of a bias where it varies faster than linearly within the window
// (measured: docs/features.md, bench/results/denoise.md).
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

// The filter fits a + b u + c v to the window's indirect light by weighted least squares, (u, v) a
// neighbour's offset in the texel's plane in world texel sizes, and keeps a, the fit at the texel:
// light that varies linearly across the window is kept exactly, where a weighted mean is biased
// toward the side with more weight (along a falloff, at a chart border, in a corner). Measured on
// the CPU's per-bounce bakes (bench/results/denoise.md, "Linear fit"): the Cornell room's error at
// 256 and 1024 spp 1.8x and 1.1x below the unfiltered bake's, where the weighted mean's was 1.1x and
// 1.9x above it.

// A neighbour's offset from the texel in the texel's plane (unit `normal`), in units of `texel_size`.
EXITANCE_FN vec2 texture_space_filter_plane_offset(vec3 normal, vec3 offset, float texel_size) {
  vec3 helper = abs(normal.x) < 0.9f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f);
  vec3 e1 = normalize(cross(normal, helper));
  vec3 e2 = cross(normal, e1);
  float scale = texel_size > 0.0f ? 1.0f / texel_size : 1.0f;
  return vec2(dot(offset, e1) * scale, dot(offset, e2) * scale);
}

// The fit's determinant must be at least this times m00^3 (m00 the weights' sum): below it the
// window's offsets do not span the plane (a chart a texel or so wide) and the weighted mean is used.
const float kFilterLinearSpan = 0.05f;

// The first row (c0, c1, c2) of M^-1, M = sum_j w_j p_j p_j^T with p_j = (1, u_j, v_j) given by its
// six entries: the fit at the texel is sum_j w_j (c0 + c1 u_j + c2 v_j) x_j, whose weights sum to 1.
// False (and c = (0, 0, 0)) where the offsets do not span the plane (kFilterLinearSpan).
EXITANCE_FN bool texture_space_filter_linear_row(double m00, double m01, double m02, double m11, double m12, double m22,
                                                 OUT(double) c0, OUT(double) c1, OUT(double) c2) {
  double k0 = m11 * m22 - m12 * m12;
  double k1 = m12 * m02 - m01 * m22;
  double k2 = m01 * m12 - m11 * m02;
  double det = m00 * k0 + m01 * k1 + m02 * k2;
  c0 = 0.0;
  c1 = 0.0;
  c2 = 0.0;
  if (!(det > double(kFilterLinearSpan) * m00 * m00 * m00)) return false;
  c0 = k0 / det;
  c1 = k1 / det;
  c2 = k2 / det;
  return true;
}

// Whether a texel takes the fit rather than the weighted mean: the one with the smaller estimated
// squared error. A fit of three parameters has the larger variance (and at a small chart's edge,
// extrapolated, much larger); the mean has a bias wherever the light is not flat. With W = sum w,
// Q = sum w^2 V p p^T (V a neighbour's variance of the mean summed over the channels, p = (1, u, v)
// as above) and c the fit's row: Var(mean) = Q00 / W^2, Var(fit) = c^T Q c, Cov = (c . Q_0) / W, and
// E|mean - fit|^2 = bias^2 + Var(mean) + Var(fit) - 2 Cov; so the fit's error is the smaller when
// |mean - fit|^2 (`difference_squared`, summed over the channels) > kFilterFitMargin (2 Var(fit) -
// 2 Cov). Measured: bench/results/denoise.md, "Linear fit".
const float kFilterFitMargin = 1.0f;

EXITANCE_FN bool texture_space_filter_prefers_fit(double difference_squared, double weight_sum, double q00, double q01,
                                                  double q02, double q11, double q12, double q22, double c0, double c1,
                                                  double c2) {
  double fit_variance = c0 * c0 * q00 + c1 * c1 * q11 + c2 * c2 * q22 +
                        2.0 * (c0 * c1 * q01 + c0 * c2 * q02 + c1 * c2 * q12);
  double covariance = (c0 * q00 + c1 * q01 + c2 * q02) / weight_sum;
  return difference_squared > double(kFilterFitMargin) * 2.0 * (fit_variance - covariance);
}

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
// noise explains weigh less, exp(-|x_j - x_i|^2 / (2 k^2 V)) with k kFilterRangeSigmas and V the
// difference's variance as texture_space_filter_range_variance counts it, squares and variances of
// the mean summed over the channels. Geometry cannot see an occluder resting on a surface (a box on
// a floor): the floor under it is black, its neighbours lit, all on one plane; their difference is
// many standard errors, so no light leaks in. Two exact values (no variance) mix only if equal.
// The variance of a texel's and a neighbour's difference as the range weight counts it: V_i + V_j,
// with the neighbour's part at most kFilterNeighbourVariance V_i. A neighbour lit by one rare path
// (a large mean with a large variance) is so kept out of texels whose own noise does not explain
// it; with V_i + V_j alone it was let in and spread over the window (thin_walls at 16 texels/m, 16
// spp of path tracing: 22x the unfiltered relMSE; bench/results/denoise.md, "Linear fit").
const float kFilterNeighbourVariance = 3.0f;
EXITANCE_FN float texture_space_filter_range_variance(float own_variance, float neighbour_variance) {
  return own_variance + min(neighbour_variance, kFilterNeighbourVariance * own_variance);
}

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
