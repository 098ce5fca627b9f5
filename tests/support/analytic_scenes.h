// The analytic scenes of DESIGN §6.1, shared by the CPU reference's analytic tests and the
// Vulkan cross-checks: geometry, the texels where the answer is known, and that answer.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "exitance/common/sampling.h"
#include "support/test_scenes.h"

namespace exitance::testing {

struct AnalyticScene {
  Scene scene;
  TexelGBuffer gbuffer;
  std::vector<double> exact;  // per texel, E/pi for a unit-colour source; channel c is exact * colour[c]
  Vec3 colour{1, 1, 1};
};

// Centres of an n x n grid on [margin, 1 - margin]^2.
inline std::vector<Vec2> grid_points(int n, float margin) {
  std::vector<Vec2> points;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      points.push_back({margin + (1 - 2 * margin) * (float(i) + 0.5f) / float(n),
                        margin + (1 - 2 * margin) * (float(j) + 0.5f) / float(n)});
  return points;
}

// Form factor from a differential area to a parallel rectangle with one corner above it
// (sides a, b at distance d): the classic closed form.
inline double corner_form_factor(double a, double b, double d) {
  const double x = a / d, y = b / d;
  const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * kPi);
}

// Superposition of four corner rectangles for a rectangle [x0,x1] x [z0,z1] seen from the origin.
inline double point_to_rectangle_form_factor(double x0, double x1, double z0, double z1, double d) {
  auto f = [&](double x, double z) {
    const double s = (x < 0 ? -1.0 : 1.0) * (z < 0 ? -1.0 : 1.0);
    return s * corner_form_factor(std::fabs(x), std::fabs(z), d);
  };
  return f(x1, z1) - f(x0, z1) - f(x1, z0) + f(x0, z0);
}

// Closed-form form factor between two coaxial parallel unit squares one unit apart.
inline double unit_squares_form_factor() {
  const double x = 1.0, y = 1.0;  // sides over distance
  const double a = std::sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y));
  return 2.0 / (kPi * x * y) *
         (std::log(a) + x * std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y)) +
          y * std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) - x * std::atan(x) - y * std::atan(y));
}

// Closed unit box, every face emitting Le one-sided inward with albedo rho: E/pi = Le / (1 - rho).
inline AnalyticScene white_furnace(float albedo) {
  AnalyticScene a;
  a.colour = {1.0f, 0.5f, 0.25f};
  add_inward_box(a.scene, {0, 0, 0}, {1, 1, 1}, add_material(a.scene, {albedo, albedo, albedo}, a.colour));
  for (Vec2 p : grid_points(4, 0.1f)) {
    a.gbuffer.texels.push_back(texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));   // floor
    a.gbuffer.texels.push_back(texel_at({p.x, p.y, 0.0f}, {0, 0, 1}));   // back wall
    a.gbuffer.texels.push_back(texel_at({1.0f, p.x, p.y}, {-1, 0, 0}));  // right wall
    a.gbuffer.texels.push_back(texel_at({p.x, 1.0f, p.y}, {0, -1, 0}));  // ceiling
  }
  a.exact.assign(a.gbuffer.texels.size(), 1.0 / (1.0 - albedo));
  return a;
}

// An upward plane alone under a constant sky: E/pi equals the sky radiance, with zero variance.
inline AnalyticScene plane_under_constant_sky() {
  AnalyticScene a;
  add_quad(a.scene, {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, add_material(a.scene, {0.8f, 0.8f, 0.8f}));
  a.scene.sky.constant = a.colour = {0.5f, 1.0f, 2.0f};
  for (Vec2 p : grid_points(8, 0.0f)) a.gbuffer.texels.push_back(texel_at({2 * p.x - 1, 0, 2 * p.y - 1}, {0, 1, 0}));
  a.exact.assign(a.gbuffer.texels.size(), 1.0);
  return a;
}

// Point light of intensity (10, 20, 5) above a plane: E/pi = I cos(theta) / (pi d^2).
inline AnalyticScene point_light_over_plane() {
  AnalyticScene a;
  add_quad(a.scene, {-4, 0, 4}, {8, 0, 0}, {0, 0, -8}, add_material(a.scene, {0.7f, 0.7f, 0.7f}));
  PunctualLight light;
  light.type = PunctualLight::Type::Point;
  light.position = {0.3f, 2.0f, -0.2f};
  light.intensity = {10.0f, 20.0f, 5.0f};
  a.scene.lights.push_back(light);
  a.colour = {1.0f, 2.0f, 0.5f};  // exact holds the red channel
  for (Vec2 p : grid_points(6, 0.0f)) {
    const Vec3 x{6 * p.x - 3, 0, 6 * p.y - 3};
    a.gbuffer.texels.push_back(texel_at(x, {0, 1, 0}));
    const Vec3 d = light.position - x;
    const double dist2 = dot(d, d), cos_theta = d.y / std::sqrt(dist2);
    a.exact.push_back(10.0 * cos_theta / (kPi * dist2));
  }
  return a;
}

// Spot light 2 m above a black plane, cone 20..30 degrees: texels inside, on the ramp and outside.
// The last two texels lie outside the outer cone (exact 0).
inline AnalyticScene spot_light_cone_edges() {
  AnalyticScene a;
  add_quad(a.scene, {-4, 0, 4}, {8, 0, 0}, {0, 0, -8}, add_material(a.scene, {0.0f, 0.0f, 0.0f}));
  PunctualLight spot;
  spot.type = PunctualLight::Type::Spot;
  spot.position = {0, 2, 0};
  spot.direction = {0, -1, 0};
  spot.intensity = {50, 50, 50};
  const double inner = 20.0 * kPi / 180.0, outer = 30.0 * kPi / 180.0;
  spot.cos_inner = float(std::cos(inner));
  spot.cos_outer = float(std::cos(outer));
  a.scene.lights.push_back(spot);
  for (double degrees : {0.0, 10.0, 19.5, 21.0, 25.0, 29.0, 30.5, 40.0}) {
    const double angle = degrees * kPi / 180.0;
    const double r = 2.0 * std::tan(angle);
    a.gbuffer.texels.push_back(texel_at({float(r), 0, 0}, {0, 1, 0}));
    const double cd = std::cos(angle);
    const double t = std::clamp((cd - std::cos(outer)) / (std::cos(inner) - std::cos(outer)), 0.0, 1.0);
    const double dist2 = 4.0 + r * r;
    a.exact.push_back(50.0 * t * t * cd / (kPi * dist2));
  }
  return a;
}

// Directional light of irradiance (3, 2, 1) on an upward plane: E/pi = E cos(theta) / pi.
inline AnalyticScene directional_light_on_plane() {
  AnalyticScene a;
  add_quad(a.scene, {-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, add_material(a.scene, {0.5f, 0.5f, 0.5f}));
  PunctualLight sun;
  sun.type = PunctualLight::Type::Directional;
  sun.direction = normalize(Vec3{0.3f, -0.8f, 0.52f});
  sun.intensity = a.colour = {3.0f, 2.0f, 1.0f};
  a.scene.lights.push_back(sun);
  for (Vec2 p : grid_points(4, 0.1f)) a.gbuffer.texels.push_back(texel_at({4 * p.x - 2, 0, 4 * p.y - 2}, {0, 1, 0}));
  a.exact.assign(a.gbuffer.texels.size(), -sun.direction.y / kPi);
  return a;
}

// Black receiver square at y=0 facing up, emitter square of radiance (2, 1, 0.5) at y=1 facing
// down: E/pi at a receiver point is Le times its point-to-rectangle form factor.
inline AnalyticScene two_parallel_unit_squares() {
  AnalyticScene a;
  a.colour = {2.0f, 1.0f, 0.5f};
  add_quad(a.scene, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, add_material(a.scene, {0, 0, 0}));
  add_quad(a.scene, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, add_material(a.scene, {0, 0, 0}, a.colour));
  for (Vec2 p : grid_points(8, 0.0f)) {
    a.gbuffer.texels.push_back(texel_at({p.x, 0, p.y}, {0, 1, 0}));
    a.exact.push_back(point_to_rectangle_form_factor(-p.x, 1 - p.x, -p.y, 1 - p.y, 1.0));
  }
  return a;
}

// Black floor and walls under an emissive ceiling: no closed form, but indirect light must be 0.
inline AnalyticScene albedo_zero_room() {
  AnalyticScene a;
  Scene& s = a.scene;
  const uint32_t black = add_material(s, {0, 0, 0});
  add_quad(s, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, black);                              // floor
  add_quad(s, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, add_material(s, {0, 0, 0}, {1, 1, 1}));  // emissive ceiling
  add_quad(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, black);                               // back wall
  add_quad(s, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, black);                               // left wall
  for (Vec2 p : grid_points(4, 0.1f)) {
    a.gbuffer.texels.push_back(texel_at({p.x, 0, p.y}, {0, 1, 0}));
    a.gbuffer.texels.push_back(texel_at({p.x, p.y, 0}, {0, 0, 1}));
  }
  return a;
}

}  // namespace exitance::testing
