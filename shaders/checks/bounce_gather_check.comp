// Compile-only check: runtime/common's per-bounce math (bounce_gather.h) stays valid GLSL, ready for
// a Vulkan per-bounce kernel. Built by the target exitance_glsl_checks; never dispatched.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "exitance/common/bounce_gather.h"
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer Result { vec4 result[]; };
void main() {
  BilinearFootprint f = bilinear_footprint(lightmap_page_uv(vec2(0.3f, 0.4f), vec4(0.5f, 0.5f, 0.1f, 0.2f)), 64, 32);
  result[0] = vec4(float(f.x0), float(f.y0), bilinear_weight(f, 1, 0), geometric_tail_factor(0.5f));
}
