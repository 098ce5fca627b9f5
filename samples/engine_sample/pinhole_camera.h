// exitance-view's pinhole camera (docs/view.md) as a Vulkan view-projection matrix: the ray through
// image point (x, y), in pixels from the top-left, is
//   normalize(forward + right (2x/W - 1) tan(yfov/2) W/H + up (1 - 2y/H) tan(yfov/2)),
// so a point projects to x = W/2 (1 + x_cam / (z tan W/H)), y = H/2 (1 - y_cam / (z tan)).
#pragma once
#include <array>
#include <cstdint>

namespace engine_sample {

// Column-major (GLSL's mat4). Vulkan's framebuffer y grows downwards, so clip y = -y_cam: row 0 of
// the image is the top. Depth is reversed and infinite (z_ndc = near / z_cam; clear 0, test
// GREATER): no far plane, as a ray caster has none, and float depth keeps its precision far away.
// Throws UsageError for a camera exitance-view refuses (no view direction, up parallel to it).
std::array<float, 16> view_projection(const std::array<double, 3>& look_from, const std::array<double, 3>& look_at,
                                      const std::array<double, 3>& up, double yfov, uint32_t width, uint32_t height);

}  // namespace engine_sample
