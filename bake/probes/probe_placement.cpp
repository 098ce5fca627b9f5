#include "exitance/bake/probes/probe_placement.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "exitance/runtime/world_box.h"

namespace exitance {
namespace {

// Evenly spread unit directions (golden-angle spiral): deterministic, no clustering.
std::vector<Vec3> fibonacci_sphere(uint32_t count) {
  std::vector<Vec3> dirs(count);
  const float golden = 2.39996322972865332f;
  for (uint32_t i = 0; i < count; ++i) {
    const float z = 1.0f - 2.0f * (float(i) + 0.5f) / float(count);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    dirs[i] = {r * std::cos(golden * float(i)), r * std::sin(golden * float(i)), z};
  }
  return dirs;
}

enum class Site { Free, Inside };

struct SiteTester {
  const Scene& scene;
  const EmbreeScene& embree;
  const formats::SparseVoxelOctree* svo;
  std::vector<Vec3> directions;
  float inside_fraction;

  Site classify(Vec3 p) const {
    if (svo && !svo->nodes.empty()) {
      const uint32_t node = formats::svo_find_node(*svo, {p.x, p.y, p.z}, svo->depth);
      if (node != formats::kSvoNoParent && svo->nodes[node].level == svo->depth) return Site::Inside;
    }
    uint32_t backfaces = 0;
    for (const Vec3& d : directions) {
      const Hit hit = embree.intersect(p, d, std::numeric_limits<float>::infinity());
      if (!hit.found) continue;
      const bool front = dot(d, hit.geometric_normal) < 0;
      if (!front && !scene.materials[scene.triangle_material[hit.triangle]].double_sided) ++backfaces;
    }
    return float(backfaces) > inside_fraction * float(directions.size()) ? Site::Inside : Site::Free;
  }
};

}  // namespace

float automatic_probe_spacing(const Scene& scene) {
  const WorldBox b = scene_world_box(scene);
  if (b.empty()) return 1.0f;
  const float extent = std::max({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z});
  return extent > 0 && std::isfinite(extent) ? extent / 12.0f : 1.0f;
}

ProbePlacement place_probes(const Scene& scene, const EmbreeScene& embree, const formats::SparseVoxelOctree* svo,
                            const ProbePlacementSettings& settings) {
  ProbePlacement placement;
  placement.automatic_spacing = !(settings.spacing > 0);
  if (settings.spacing < 0 || !std::isfinite(settings.spacing))
    throw std::invalid_argument("probe spacing must be a positive number");
  const float spacing = placement.automatic_spacing ? automatic_probe_spacing(scene) : settings.spacing;
  const WorldBox b = scene_world_box(scene);
  formats::ProbeGrid& grid = placement.grid;
  grid.spacing = {spacing, spacing, spacing};
  if (b.empty()) return placement;
  // Probes at cell centres of a grid of whole spacings, centred on the bounds, so none sits on the
  // bounding walls of a room. An axis thinner than half a spacing (a flat scene) gets two layers,
  // one on each side, rather than one in the plane of the geometry.
  uint64_t total = 1;
  for (int a = 0; a < 3; ++a) {
    const double extent = double(b.hi[a]) - double(b.lo[a]);
    const double cells = extent < 0.5 * double(spacing) ? 2.0 : std::max(1.0, std::ceil(extent / double(spacing)));
    if (!(cells <= double(settings.max_probes))) total = settings.max_probes + 1;
    grid.counts[a] = uint32_t(std::min(cells, double(settings.max_probes)));
    total = std::min<uint64_t>(total * grid.counts[a], settings.max_probes + 1);
    grid.origin[a] = float(0.5 * (double(b.lo[a]) + double(b.hi[a])) - 0.5 * double(grid.counts[a] - 1) * spacing);
  }
  if (total > settings.max_probes)
    throw std::invalid_argument("probe spacing " + std::to_string(spacing) + " gives more than " +
                                std::to_string(settings.max_probes) + " probes; use a larger spacing");
  grid.probes.resize(total);

  // Occupancy says "within a leaf of a surface"; with leaves coarser than a quarter spacing that
  // would move probes that are comfortably in free space, so then the rays alone decide.
  const bool use_occupancy = svo && !svo->nodes.empty() && svo->voxel_size(svo->depth) <= 0.25f * spacing;
  const SiteTester tester{scene,
                          embree,
                          use_occupancy ? svo : nullptr,
                          fibonacci_sphere(std::max<uint32_t>(8, settings.test_rays)),
                          settings.inside_backface_fraction};
  // Far from geometry: no triangle within the skip distance by a real distance query (Embree's
  // point query, not grown bounding boxes: a long diagonal triangle's box reaches far from it), and
  // in the open: more than a quarter of the test rays escape. Without the second test the middle of
  // any room more than 6 spacings across (every room at the automatic spacing) would lose its
  // probes, which dynamic objects there need; a closed room lets no ray out.
  const float skip_distance = settings.skip_distance_in_spacings * spacing;
  auto far_from_geometry = [&](Vec3 p) {
    if (!(settings.skip_distance_in_spacings > 0)) return false;
    if (std::isfinite(embree.distance_to_nearest_triangle(p, skip_distance))) return false;
    size_t escaped = 0;
    for (const Vec3& d : tester.directions) escaped += !embree.occluded(p, d, std::numeric_limits<float>::infinity());
    return 4 * escaped > tester.directions.size();
  };
  // Move candidates: 26 lattice directions at growing radii up to half a spacing, nearest first.
  std::vector<Vec3> offsets;
  for (float radius : {0.125f, 0.25f, 0.375f, 0.5f})
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
          if (!x && !y && !z) continue;
          const Vec3 d{float(x), float(y), float(z)};
          offsets.push_back(d * (radius * spacing / length(d)));
        }
  std::stable_sort(offsets.begin(), offsets.end(), [](Vec3 a, Vec3 b) { return length(a) < length(b); });

  tbb::parallel_for(size_t(0), grid.probes.size(), [&](size_t i) {
    const uint32_t x = uint32_t(i % grid.counts[0]);
    const uint32_t y = uint32_t((i / grid.counts[0]) % grid.counts[1]);
    const uint32_t z = uint32_t(i / (size_t(grid.counts[0]) * grid.counts[1]));
    const Vec3 p{grid.origin[0] + float(x) * spacing, grid.origin[1] + float(y) * spacing,
                 grid.origin[2] + float(z) * spacing};
    formats::ProbeRecord& record = grid.probes[i];
    record.position = {p.x, p.y, p.z};
    if (far_from_geometry(p)) {
      record.state = formats::ProbeState::Skipped;
      return;
    }
    if (tester.classify(p) == Site::Free) {
      record.state = formats::ProbeState::Valid;
    } else {
      record.state = formats::ProbeState::Invalid;
      for (const Vec3& offset : offsets) {
        const Vec3 q = p + offset;
        if (tester.classify(q) == Site::Free) {
          record.position = {q.x, q.y, q.z};
          record.state = formats::ProbeState::Moved;
          break;
        }
      }
    }
  });
  for (const formats::ProbeRecord& r : grid.probes) {
    switch (r.state) {
      case formats::ProbeState::Valid: ++placement.valid; break;
      case formats::ProbeState::Moved: ++placement.moved; break;
      case formats::ProbeState::Invalid: ++placement.invalid; break;
      case formats::ProbeState::Skipped: ++placement.skipped; break;
    }
  }
  return placement;
}

}  // namespace exitance
