// The per-bounce mode's shared math (issue 10, seed 003 ch. 3-4), for the CPU backend
// (runtime/src/cpu/cpu_bounce_integrator.cpp) and the Vulkan kernels (shaders/include/bounce_pass.glsl): where a gather ray's hit
// reads a bounce layer in the atlas, and the geometric extrapolation of the bounces not run.
//
// B_k(x) = E_k(x)/pi, the irradiance over pi from light that bounced k times. With cosine-sampled
// directions w_j (pdf cos/pi) the estimator of the next bounce is B_{k+1}(x) = 1/N sum_j L_o,k(y_j)
// with L_o,k(y) = albedo(y) B_k(y): the cosine and the pi cancel (seed 003's pseudo-code instead
// scales uniform-hemisphere samples wrongly; see the digest). A miss adds 0 for k + 1 >= 1: the sky
// is direct light, already in B_0; emitters' Le enters only B_0.
#ifndef EXITANCE_COMMON_BOUNCE_GATHER_H
#define EXITANCE_COMMON_BOUNCE_GATHER_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

// Random streams of bounce pass k >= 1: path_sampler(seed, kBounceRngStreamBase * k + texel, sample),
// apart from the texels' B_0 streams (texel) and the probes' (kProbeRngStreamBase + probe, 2^40).
const uint64_t kBounceRngStreamBase = 17592186044416ul;  // 2^44

// A lightmap UV on its instance's page: uv * s + o (the manifest's scale_offset = s.x, s.y, o.x, o.y).
EXITANCE_FN vec2 lightmap_page_uv(vec2 lightmap_uv, vec4 scale_offset) {
  return vec2(lightmap_uv.x * scale_offset.x + scale_offset.z, lightmap_uv.y * scale_offset.y + scale_offset.w);
}

// Bilinear footprint of a page UV on a width x height page whose texel (x, y) has its centre at
// ((x + 0.5) / width, (y + 0.5) / height): texels (x0 .. x0 + 1, y0 .. y0 + 1) with weights
// (1 - fx, fx) x (1 - fy, fy). Texels outside the page, or not lit, are left out by the caller and
// the remaining weights renormalised.
struct BilinearFootprint {
  int x0;
  int y0;
  float fx;
  float fy;
};

EXITANCE_FN BilinearFootprint bilinear_footprint(vec2 page_uv, int width, int height) {
  float px = page_uv.x * float(width) - 0.5f;
  float py = page_uv.y * float(height) - 0.5f;
  BilinearFootprint f;
  float fx0 = floor(px);
  float fy0 = floor(py);
  f.x0 = int(fx0);
  f.y0 = int(fy0);
  f.fx = px - fx0;
  f.fy = py - fy0;
  return f;
}

// A footprint texel is on the hit's surface when its normal is within ~37 degrees of the hit's and
// it lies near the hit's tangent plane (within ~14 degrees seen from the hit): thresholds loose
// enough for curved surfaces at coarse texels, tight enough to drop the next face of a box.
const float kSameSurfaceCosine = 0.8f;
const float kPlaneSlope = 0.25f;

// Whether a footprint texel (centre `texel_position`, normal `texel_normal`, any length) is on the
// surface hit at `position` with unit normal `normal`, by the two thresholds above.
EXITANCE_FN bool texel_on_hit_surface(vec3 texel_position, vec3 texel_normal, vec3 position, vec3 normal) {
  vec3 d = texel_position - position;
  return !(dot(texel_normal, normal) < kSameSurfaceCosine * length(texel_normal)) &&
         !(abs(dot(d, normal)) > kPlaneSlope * length(d));
}

// A footprint whose usable texels carry no more bilinear weight than this gives no value: the
// renormalisation would amplify one texel's noise.
const float kLeastFootprintWeight = 1e-3f;

// Weight of corner (dx, dy) in {0, 1}^2 of a footprint.
EXITANCE_FN float bilinear_weight(BilinearFootprint f, int dx, int dy) {
  float wx = dx == 0 ? 1.0f - f.fx : f.fx;
  float wy = dy == 0 ? 1.0f - f.fy : f.fy;
  return wx * wy;
}

// The bounces after the last one run, extrapolated geometrically from the ratio r of the last two
// (B_{k+1} ~ r B_k): sum_{j>=1} r^j B_k = B_k r / (1 - r). Infinite when r >= 1 (no decay seen yet).
// At albedo 0.99 r -> 0.99 and the tail is ~100x the last bounce: a small last bounce does not mean
// the rest is small.
EXITANCE_FN float geometric_tail_factor(float ratio) {
  if (!(ratio < 1.0f)) return uintBitsToFloat(0x7F800000u);
  return max(ratio, 0.0f) / (1.0f - max(ratio, 0.0f));
}

EXITANCE_NAMESPACE_END
#endif
