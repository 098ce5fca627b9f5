// GLSL twin of runtime/include/exitance/runtime/ray_offset.h (pbrt-v4 §6.8.6 error bounds).
const float kRelativePositionError = 4.2e-7;
const float kScenePositionErrorFloor = 1e-6;

float next_float_toward(float x, float direction) {
  if (direction == 0.0) return x;
  if (x == 0.0) return direction > 0.0 ? uintBitsToFloat(1u) : -uintBitsToFloat(1u);
  uint bits = floatBitsToUint(x);
  // Moving away from zero adds one to the magnitude's bits; toward zero subtracts one.
  bool away = (x > 0.0) == (direction > 0.0);
  return uintBitsToFloat(away ? bits + 1u : bits - 1u);
}

vec3 offset_ray_origin(vec3 p, vec3 n, float scene_extent) {
  float floor_error = kScenePositionErrorFloor * scene_extent;
  vec3 error = kRelativePositionError * abs(p) + vec3(floor_error);
  float distance = dot(abs(n), error);
  vec3 moved = p + n * distance;
  return vec3(next_float_toward(moved.x, n.x), next_float_toward(moved.y, n.y), next_float_toward(moved.z, n.z));
}
