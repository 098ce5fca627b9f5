// Extensions, constants and small math shared by every kernel. Mirrors runtime/include/exitance/runtime/
// {vec_math.h, sampling.h}: same formulas, same constants, so the GPU computes the CPU's estimator.
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

const float kPi = 3.14159265358979323846;
const float kInvPi = 0.31830988618379067154;
const float kInfinity = 1.0 / 0.0;  // +inf (glslang folds it)
const uint kInvalid = 0xFFFFFFFFu;

float max_component(vec3 a) { return max(a.x, max(a.y, a.z)); }
float luminance(vec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// Duff et al. 2017 (vec_math.h orthonormal_basis).
void orthonormal_basis(vec3 n, out vec3 t, out vec3 b) {
  float sign_z = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;  // std::copysign(1, n.z), -0.0 included
  float a = -1.0 / (sign_z + n.z);
  float bb = n.x * n.y * a;
  t = vec3(1.0 + sign_z * n.x * n.x * a, sign_z * bb, -sign_z * n.x);
  b = vec3(bb, sign_z + n.y * n.y * a, -n.y);
}
