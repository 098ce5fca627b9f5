// The common subset of C++ and GLSL. Headers in this folder are compiled by the C++ build and
// included by glslang (GL_GOOGLE_include_directive), the way NanoVDB's PNanoVDB.h serves C and
// GLSL: one text of the math, so host and shader cannot drift, and the CPU tests cover the shaders.
//
// Rules for code in runtime/common (checked by both compilers):
//  - types vec2/vec3/vec4, uint, uint64_t; constructors vec3(x, y, z) and vec3(s); no swizzles;
//  - float literals with an f suffix (C++ would otherwise compute in double and round differently);
//  - EXITANCE_FN before every function (C++ inline), INOUT(T)/OUT(T) for GLSL inout/out parameters;
//  - structs are filled member by member (GLSL constructors and C++ braces differ);
//  - every random number is drawn into a named variable before use: C++ leaves the order of
//    evaluation of function arguments unspecified, GLSL does not.
//  - scene data is read through accessor functions (scene_access.h) that take SCENE_PARAM.
#ifdef __cplusplus
// First, outside the guard: vec_math.h includes vector_functions.h, which needs this header complete.
#include "exitance/runtime/vec_math.h"
#endif

#ifndef EXITANCE_COMMON_DIALECT_H
#define EXITANCE_COMMON_DIALECT_H

#ifdef __cplusplus

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#define EXITANCE_FN inline
#define INOUT(T) T&
#define OUT(T) T&
#define OUT_ARRAY(T, name, n) T (&name)[n]

namespace exitance {

struct LightingScene;  // the CPU side of the scene accessors (runtime/.../cpu/scene_access.h)
#define SCENE_PARAM const ::exitance::LightingScene &scene,
#define SCENE_ALONE_PARAM const ::exitance::LightingScene &scene
#define SCENE_ARG scene,
#define SCENE_ALONE_ARG scene

using uint = uint32_t;
using vec2 = Vec2;
using vec3 = Vec3;
using vec4 = Vec4;

// GLSL built-ins used by the common headers, with GLSL's semantics on finite values.
inline float abs(float a) { return std::fabs(a); }
inline float min(float a, float b) { return b < a ? b : a; }
inline float max(float a, float b) { return a < b ? b : a; }
inline uint min(uint a, uint b) { return b < a ? b : a; }
inline uint max(uint a, uint b) { return a < b ? b : a; }
inline int max(int a, int b) { return a < b ? b : a; }
inline float clamp(float x, float lo, float hi) { return min(max(x, lo), hi); }
inline float sqrt(float a) { return std::sqrt(a); }
inline double sqrt(double a) { return std::sqrt(a); }
inline double min(double a, double b) { return b < a ? b : a; }
inline double max(double a, double b) { return a < b ? b : a; }
inline double clamp(double x, double lo, double hi) { return min(max(x, lo), hi); }
inline float acos(float a) { return std::acos(a); }
inline float floor(float a) { return std::floor(a); }
inline float cos(float a) { return std::cos(a); }
inline float exp(float a) { return std::exp(a); }
inline float sin(float a) { return std::sin(a); }
// GLSL's two-argument atan is C's atan2.
inline float atan(float y, float x) { return std::atan2(y, x); }
inline bool isinf(float a) { return std::isinf(a); }
inline bool isnan(float a) { return std::isnan(a); }
inline uint floatBitsToUint(float f) { return std::bit_cast<uint>(f); }
inline float uintBitsToFloat(uint u) { return std::bit_cast<float>(u); }
inline uint bitfieldReverse(uint x) {
  x = ((x >> 1u) & 0x55555555u) | ((x & 0x55555555u) << 1u);
  x = ((x >> 2u) & 0x33333333u) | ((x & 0x33333333u) << 2u);
  x = ((x >> 4u) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4u);
  x = ((x >> 8u) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8u);
  return (x >> 16u) | (x << 16u);
}
inline vec3 abs(vec3 a) { return vec3(std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)); }

}  // namespace exitance

#define EXITANCE_NAMESPACE_BEGIN namespace exitance {
#define EXITANCE_NAMESPACE_END }

#else  // GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#define EXITANCE_FN
#define INOUT(T) inout T
#define OUT(T) out T
#define OUT_ARRAY(T, name, n) out T name[n]
#define EXITANCE_NAMESPACE_BEGIN
#define EXITANCE_NAMESPACE_END
// The scene lives in the descriptor set: accessors take no scene argument.
#define SCENE_PARAM
#define SCENE_ALONE_PARAM
#define SCENE_ARG
#define SCENE_ALONE_ARG

#endif

#endif  // EXITANCE_COMMON_DIALECT_H
