#include "exitance/bake/bundle/automatic_view.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "exitance/runtime/core/bvh4_walk.h"
#include "exitance/runtime/view/view_render.h"

namespace exitance {
namespace {

// Small enough to cost milliseconds per candidate, large enough that the fractions are stable.
constexpr int kTestSize = 48;
// From outside, a scene is shown when at least 10 % of the pixels hit it and half of those are lit.
constexpr double kEnoughHits = 0.1, kEnoughLitHits = 0.5;
constexpr double kOutsideYfov = 0.8727;  // 50 degrees
constexpr double kInsideYfov = 1.3963;   // 80 degrees: a room seen from its corner
// A view whose median surface is nearer than this fraction of the scene's largest extent is a
// close-up of a wall; its score is scaled down in proportion.
constexpr double kCloseUpFraction = 0.15;

struct Score {
  double hit_fraction = 0;     // pixels on a surface
  double lit_fraction = 0;     // pixels on a surface that is not black in the lightmap mode
  double median_distance = 0;  // of the pixels that hit a surface
};

// Casts the test rays through scene.bin's BVH (for the distances) and renders the lightmap mode (for
// the light: the backs of single-sided walls show black).
Score score_of(const view::ViewScene& view, const AutomaticView& candidate) {
  const view::PinholeCamera camera =
      view::look_at_camera(candidate.look_from, candidate.look_at, candidate.up, candidate.yfov);
  view::ViewRenderOptions options;
  options.width = options.height = kTestSize;
  const view::ViewImage lit = view::render_view(view, camera, options);
  const formats::SceneFile& scene = view.scene;
  const auto corners = [&](uint32_t t, Vec3& p0, Vec3& p1, Vec3& p2) {
    const auto& p = scene.triangles.positions;
    p0 = Vec3(p[3 * t][0], p[3 * t][1], p[3 * t][2]);
    p1 = Vec3(p[3 * t + 1][0], p[3 * t + 1][1], p[3 * t + 1][2]);
    p2 = Vec3(p[3 * t + 2][0], p[3 * t + 2][1], p[3 * t + 2][2]);
  };
  std::vector<uint32_t> stack;
  std::vector<double> distances;
  int lit_count = 0;
  for (int y = 0; y < kTestSize; ++y)
    for (int x = 0; x < kTestSize; ++x) {
      const Vec3 d = view::primary_ray_direction(camera, x + 0.5, y + 0.5, kTestSize, kTestSize);
      const Bvh4WalkHit hit = bvh4_closest_hit<true>(scene.bvh.nodes.data(), scene.bvh.nodes.size(),
                                                     scene.bvh.leaf_triangles.data(), corners, camera.eye, d,
                                                     std::numeric_limits<float>::infinity(), stack);
      if (!hit.found) continue;
      distances.push_back(hit.distance);
      const Vec3 c = lit.pixel(x, y);
      if (c.x + c.y + c.z > 0) ++lit_count;
    }
  Score score;
  score.hit_fraction = double(distances.size()) / double(kTestSize * kTestSize);
  score.lit_fraction = double(lit_count) / double(kTestSize * kTestSize);
  if (!distances.empty()) {
    std::nth_element(distances.begin(), distances.begin() + ptrdiff_t(distances.size() / 2), distances.end());
    score.median_distance = distances[distances.size() / 2];
  }
  return score;
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

  std::vector<AutomaticView> outside, inside;
  const std::array<std::array<float, 2>, 4> corners{{{1, 1}, {-1, 1}, {1, -1}, {-1, -1}}};
  for (const auto& corner : corners) {  // the bounding sphere fits the field of view
    const Vec3 direction = normalize(Vec3(corner[0] * box.x, 0.8f * largest, corner[1] * box.z));
    const float distance = radius / float(std::sin(kOutsideYfov / 2)) * 1.05f;
    outside.push_back({centre + direction * distance, centre, {0, 1, 0}, kOutsideYfov});
  }
  for (const auto& corner : corners) {
    const float sx = corner[0], sz = corner[1];
    // At mid-height, 0.6 of the way to a corner: across the centre, and out towards the corner (in
    // a grid of rooms, one of the two looks across a room rather than into its nearest wall).
    const Vec3 from = centre + Vec3(sx * 0.6f * box.x, 0, sz * 0.6f * box.z);
    inside.push_back({from, centre + Vec3(-sx * 0.6f * box.x, -0.3f * box.y, -sz * 0.6f * box.z), {0, 1, 0}, kInsideYfov});
    inside.push_back({from, centre + Vec3(sx * box.x, -0.3f * box.y, sz * box.z), {0, 1, 0}, kInsideYfov});
    // Near an upper corner, towards the opposite lower one.
    inside.push_back({centre + Vec3(sx * 0.8f * box.x, 0.4f * box.y, sz * 0.8f * box.z),
                      centre + Vec3(-sx * box.x, -0.6f * box.y, -sz * box.z), {0, 1, 0}, kInsideYfov});
  }
  const double close_up = kCloseUpFraction * 2 * largest;
  // The whole scene from outside when that shows it lit (the sky around it is part of the picture).
  const auto score = [&](const Score& s) { return s.lit_fraction * std::min(1.0, s.median_distance / close_up); };
  AutomaticView best_outside, best;
  double best_outside_lit = -1, best_score = -1;
  for (AutomaticView& v : outside) {
    const Score s = score_of(scene, v);
    v.lit_fraction = s.lit_fraction;
    if (s.hit_fraction >= kEnoughHits && s.lit_fraction >= kEnoughLitHits * s.hit_fraction &&
        s.lit_fraction > best_outside_lit)
      best_outside = v, best_outside_lit = s.lit_fraction;
    if (score(s) > best_score) best = v, best_score = score(s);
  }
  if (best_outside_lit >= 0) return best_outside;
  // Else the view, from inside or outside, with the most lit pixels, less for a close-up of a wall.
  for (AutomaticView& v : inside) {
    const Score s = score_of(scene, v);
    v.lit_fraction = s.lit_fraction;
    if (score(s) > best_score) best = v, best_score = score(s);
  }
  return best;
}

}  // namespace exitance
