// Texture sampling shared by the CPU reference (runtime/src/material_eval.cpp) and the kernels
// (shaders/include/scene_access.glsl): wrap modes, the bilinear footprint and KHR_texture_transform,
// written once so both backends read the same texels with the same weights. The texel fetch itself
// stays with each side (CPU: Texture's vectors; GPU: the texel buffer).
#ifndef EXITANCE_COMMON_TEXTURE_SAMPLING_H
#define EXITANCE_COMMON_TEXTURE_SAMPLING_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

// Wrap modes in the order of Texture::Wrap (runtime/include/exitance/runtime/scene.h).
const uint kWrapRepeat = 0u;
const uint kWrapClampToEdge = 1u;
const uint kWrapMirroredRepeat = 2u;

// i mod n in [0, n) for any sign of i (GLSL leaves % undefined for negative operands; integer
// division truncates toward zero in both languages).
EXITANCE_FN int floor_mod(int i, int n) {
  int m = i - (i / n) * n;
  return m < 0 ? m + n : m;
}

// The texel index that integer coordinate i (possibly outside [0, n)) reads under `wrap`.
EXITANCE_FN int wrap_texel_index(int i, int n, uint wrap) {
  if (wrap == kWrapClampToEdge) return i < 0 ? 0 : (i > n - 1 ? n - 1 : i);
  if (wrap == kWrapMirroredRepeat) {
    int m = floor_mod(i, 2 * n);
    return m < n ? m : 2 * n - 1 - m;
  }
  return floor_mod(i, n);
}

// u modulo 2^17, keeping its sign (C's fmod). Exact in float: the division and product are by a
// power of two and the difference is a multiple of u's ulp below 2^17. Keeps huge coordinates from
// overflowing int after scaling; every wrap period divides 2^17 texture widths.
EXITANCE_FN float reduced_texture_coordinate(float u) {
  float periods = u * (1.0f / 131072.0f);
  float whole = periods < 0.0f ? -floor(-periods) : floor(periods);  // truncation toward zero
  return u - 131072.0f * whole;
}

// The four texels (x0|x1, y0|y1) bilinear filtering reads at uv (glTF convention: (0, 0) is the
// top-left corner, texel centres at half-integers) and the weights tx, ty of x1 and y1.
struct BilinearTaps {
  int x0;
  int x1;
  int y0;
  int y1;
  float tx;
  float ty;
};

EXITANCE_FN BilinearTaps bilinear_taps(vec2 uv, int width, int height, uint wrap_s, uint wrap_t) {
  BilinearTaps taps;
  taps.x0 = 0;
  taps.x1 = 0;
  taps.y0 = 0;
  taps.y1 = 0;
  taps.tx = 0.0f;
  taps.ty = 0.0f;
  if (isnan(uv.x) || isinf(uv.x) || isnan(uv.y) || isinf(uv.y)) return taps;  // texel (0, 0)
  float x = reduced_texture_coordinate(uv.x) * float(width) - 0.5f;
  float y = reduced_texture_coordinate(uv.y) * float(height) - 0.5f;
  float fx = floor(x);
  float fy = floor(y);
  taps.tx = x - fx;
  taps.ty = y - fy;
  int ix = int(fx);
  int iy = int(fy);
  taps.x0 = wrap_texel_index(ix, width, wrap_s);
  taps.x1 = wrap_texel_index(ix + 1, width, wrap_s);
  taps.y0 = wrap_texel_index(iy, height, wrap_t);
  taps.y1 = wrap_texel_index(iy + 1, height, wrap_t);
  return taps;
}

// The filtered value from the texels at (x0, y0), (x1, y0), (x0, y1), (x1, y1).
EXITANCE_FN vec3 bilinear_mix(vec3 a, vec3 b, vec3 c, vec3 d, BilinearTaps taps) {
  return (a * (1.0f - taps.tx) + b * taps.tx) * (1.0f - taps.ty) + (c * (1.0f - taps.tx) + d * taps.tx) * taps.ty;
}
EXITANCE_FN float bilinear_mix(float a, float b, float c, float d, BilinearTaps taps) {
  return (a * (1.0f - taps.tx) + b * taps.tx) * (1.0f - taps.ty) + (c * (1.0f - taps.tx) + d * taps.tx) * taps.ty;
}

// KHR_texture_transform: uv' = T R S uv, rotation matrix [c s; -s c] applied to (u, v).
EXITANCE_FN vec2 transform_texture_coordinate(vec2 uv, vec2 offset, vec2 scale, float rotation) {
  if (rotation == 0.0f && scale.x == 1.0f && scale.y == 1.0f && offset.x == 0.0f && offset.y == 0.0f) return uv;
  float c = cos(rotation);
  float s = sin(rotation);
  float sx = uv.x * scale.x;
  float sy = uv.y * scale.y;
  return vec2(c * sx + s * sy + offset.x, -s * sx + c * sy + offset.y);
}

EXITANCE_NAMESPACE_END
#endif
