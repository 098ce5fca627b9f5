#include "exitance/bake/bundle/automatic_view.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "exitance/runtime/view/view_render.h"

namespace exitance {
namespace {

// Small enough to cost milliseconds per candidate, large enough that 40 % is a stable measure.
constexpr int kTestSize = 48;
constexpr double kEnoughLit = 0.4;
constexpr double kOutsideYfov = 0.8727;  // 50 degrees
constexpr double kInsideYfov = 1.3963;   // 80 degrees: a room seen from its corner

// Fraction of pixels that hit a surface (the normal mode is exactly 0 only on a miss) and show some
// light in the lightmap mode (the backs of single-sided walls show black).
double lit_fraction(const view::ViewScene& scene, const AutomaticView& candidate) {
  const view::PinholeCamera camera =
      view::look_at_camera(candidate.look_from, candidate.look_at, candidate.up, candidate.yfov);
  view::ViewRenderOptions options;
  options.width = options.height = kTestSize;
  options.mode = view::ViewMode::Normal;
  const view::ViewImage normals = view::render_view(scene, camera, options);
  options.mode = view::ViewMode::Lightmap;
  const view::ViewImage lit = view::render_view(scene, camera, options);
  int count = 0;
  for (int y = 0; y < kTestSize; ++y)
    for (int x = 0; x < kTestSize; ++x) {
      const Vec3 n = normals.pixel(x, y), c = lit.pixel(x, y);
      const bool hit = n.x != 0 || n.y != 0 || n.z != 0;
      if (hit && c.x + c.y + c.z > 0) ++count;
    }
  return double(count) / double(kTestSize * kTestSize);
}

}  // namespace

AutomaticView choose_automatic_view(const view::ViewScene& scene) {
  Vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const formats::Float3& p : scene.scene.triangles.positions) {
    lo = min(lo, Vec3(p[0], p[1], p[2]));
    hi = max(hi, Vec3(p[0], p[1], p[2]));
  }
  const Vec3 centre = (lo + hi) * 0.5f, half = (hi - lo) * 0.5f;
  // A flat scene still needs a distance: at least 1 % of the largest extent on every axis.
  const float largest = std::max({half.x, half.y, half.z, 1e-6f});
  const Vec3 box = max(half, Vec3(largest * 0.01f));
  const float radius = length(box);

  std::vector<AutomaticView> candidates;
  const std::array<std::array<float, 2>, 4> corners{{{1, 1}, {-1, 1}, {1, -1}, {-1, -1}}};
  for (const auto& corner : corners) {  // outside: the bounding sphere fits the field of view
    const Vec3 direction = normalize(Vec3(corner[0] * box.x, 0.8f * largest, corner[1] * box.z));
    const float distance = radius / float(std::sin(kOutsideYfov / 2)) * 1.05f;
    candidates.push_back({centre + direction * distance, centre, {0, 1, 0}, kOutsideYfov});
  }
  for (const auto& corner : corners) {  // inside: near an upper corner, towards the opposite lower one
    const Vec3 from = centre + Vec3(corner[0] * 0.8f * box.x, 0.4f * box.y, corner[1] * 0.8f * box.z);
    const Vec3 to = centre + Vec3(-corner[0] * box.x, -0.6f * box.y, -corner[1] * box.z);
    candidates.push_back({from, to, {0, 1, 0}, kInsideYfov});
  }
  AutomaticView best = candidates.front();
  best.lit_fraction = -1;
  for (AutomaticView& candidate : candidates) {
    candidate.lit_fraction = lit_fraction(scene, candidate);
    if (candidate.lit_fraction >= kEnoughLit) return candidate;
    if (candidate.lit_fraction > best.lit_fraction) best = candidate;
  }
  return best;
}

}  // namespace exitance
