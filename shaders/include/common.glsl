// Extensions and constants every kernel needs beyond runtime/common.
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

const float kInfinity = 1.0 / 0.0;  // +inf (glslang folds it)
const uint kInvalid = 0xFFFFFFFFu;
