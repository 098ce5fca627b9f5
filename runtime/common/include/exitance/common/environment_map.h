// An equirectangular sky (environment map) for both backends: the mapping between directions and the
// image, its nearest texel, and importance sampling by luminance x sin(theta) through a marginal CDF
// over rows and one conditional CDF per row (distribution.h's representation: normalised, n + 1
// doubles each; the rows are stored one after another, width + 1 entries apart).
// Mapping (documented in docs/cli.md): u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi, row 0 = +Y.
// C++: EnvironmentSampler (runtime/.../environment_sampler.h) builds the CDFs and calls these with
// pointers; GLSL: scene_access.glsl calls them with the environment's CDF handles, so for one
// (u1, u2) both backends pick the same texel and direction up to float rounding.
#ifndef EXITANCE_COMMON_ENVIRONMENT_MAP_H
#define EXITANCE_COMMON_ENVIRONMENT_MAP_H
#include "exitance/common/distribution.h"
#include "exitance/common/sampling.h"
EXITANCE_NAMESPACE_BEGIN

// The Vulkan backend's one environment buffer of doubles (gpu_layout.h kBindingEnvironment): the
// marginal CDF from 0, the row CDFs from environment_rows_offset, the rgb texels packed two floats
// to a double from environment_texels_offset.
EXITANCE_FN uint environment_rows_offset(uint height) { return height + 1u; }
EXITANCE_FN uint environment_texels_offset(uint width, uint height) { return height + 1u + height * (width + 1u); }

EXITANCE_FN vec2 direction_to_equirect(vec3 d) {
  float u = 0.5f + atan(d.x, -d.z) / (2.0f * kPi);
  float v = acos(clamp(d.y, -1.0f, 1.0f)) / kPi;
  return vec2(u, v);
}

EXITANCE_FN vec3 equirect_to_direction(vec2 uv) {
  float phi = (uv.x - 0.5f) * 2.0f * kPi;
  float theta = uv.y * kPi;
  float s = sin(theta);
  return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

// The cell of coordinate t in [0, 1] among n (t = 1 is the last cell).
EXITANCE_FN uint equirect_cell(float t, uint n) { return uint(clamp(t * float(n), 0.0f, float(n) - 1.0f)); }

// Nearest texel along `direction`: row * width + column.
EXITANCE_FN uint environment_texel(vec3 direction, uint width, uint height) {
  vec2 uv = direction_to_equirect(direction);
  return equirect_cell(uv.y, height) * width + equirect_cell(uv.x, width);
}

// Solid-angle density of sample_environment_direction at `direction`: the texel's probability over
// its (u, v) area, with the equirect Jacobian at the direction's own latitude (not the row centre);
// 0 at the poles.
EXITANCE_FN float environment_direction_pdf(CDF_TYPE marginal, CDF_TYPE rows, uint width, uint height, vec3 direction) {
  vec2 uv = direction_to_equirect(direction);
  uint x = equirect_cell(uv.x, width);
  uint y = equirect_cell(uv.y, height);
  double sin_theta = sqrt(max(double(0.0f), double(1.0f) - double(direction.y) * double(direction.y)));
  if (sin_theta <= double(1e-7f)) return 0.0f;
  double pdf_uv = double(cdf_pmf(marginal, y)) * double(cdf_pmf(rows + y * (width + 1u), x)) * double(width) *
                  double(height);
  return float(pdf_uv / (double(2.0f) * double(kPi) * double(kPi) * sin_theta));
}

// A direction drawn by texel probability (u1 picks the row, u2 the column), uniform in (u, v) inside
// the texel. Its pdf is environment_direction_pdf's (recomputed from the direction, as the MIS
// weights of the other strategies read it).
EXITANCE_FN vec3 sample_environment_direction(CDF_TYPE marginal, CDF_TYPE rows, uint width, uint height, float u1,
                                              float u2) {
  float row_pmf;
  uint y = sample_cdf(marginal, height, u1, row_pmf);
  float rv = cdf_remap(marginal, y, u1);
  CDF_TYPE row = rows + y * (width + 1u);
  float column_pmf;
  uint x = sample_cdf(row, width, u2, column_pmf);
  float ru = cdf_remap(row, x, u2);
  vec2 uv = vec2((float(x) + ru) / float(width), (float(y) + rv) / float(height));
  return equirect_to_direction(uv);
}

EXITANCE_NAMESPACE_END
#endif
