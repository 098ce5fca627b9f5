#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "generate": fills every path slot at the start of a batch.
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

void main() {
  uint p = gl_GlobalInvocationID.x;
  if (p >= params.path_capacity) return;
  regenerate(p);
}
