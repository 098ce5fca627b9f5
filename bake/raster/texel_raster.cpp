#include "exitance/bake/raster/texel_raster.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "exitance/bake/raster/cell_rejection.h"
#include "exitance/formats/scene_file.h"  // texel_morton_code: the order scene.bin stores texels in
#include "exitance/runtime/texel_surface.h"

namespace exitance {
namespace {

struct TexelCandidate {
  float best_area = 0;
  float coverage = 0;
  uint32_t triangle = 0;
  Vec2 centroid;
};

// A cell some chart covers, with what its best triangle gave it.
struct LiveCell {
  uint32_t morton = 0;  // the cell's place in scene.bin's order within its page
  uint32_t cell = 0;    // y * page width + x
  uint32_t triangle = 0;
  Vec2 centroid;
};

}  // namespace

TexelGBuffer rasterize_texel_gbuffer(const Scene& scene, const AtlasLayout& layout, const std::string& file,
                                     Diagnostics& diagnostics, const FractionDone& progress) {
  TexelGBuffer gbuffer;
  gbuffer.instance_rects = layout.rects;
  for (const auto& [w, h] : layout.page_sizes) {
    AtlasPage page;
    page.width = w;
    page.height = h;
    gbuffer.pages.push_back(std::move(page));
  }
  // Pages are mostly empty at scale (a 10 M-texel atlas holds ~100 M cells): clearing their
  // coverage is a large part of the stage, so it runs in parallel too.
  tbb::parallel_for(size_t(0), gbuffer.pages.size(), [&](size_t p) {
    gbuffer.pages[p].coverage.assign(size_t(gbuffer.pages[p].width) * size_t(gbuffer.pages[p].height), 0.0f);
  });
  // Progress: rasterizing the triangles is the first half, filling in the pages' texels the second.
  auto part = [&](double start, double share) -> FractionDone {
    if (!progress) return {};
    return [&progress, start, share](double fraction) { progress(start + share * fraction); };
  };
  ParallelProgress done(part(0.0, 0.5), scene.triangle_count());
  std::vector<float> triangle_texel_size(scene.triangle_count(), 0.0f);
  // Instances in parallel: each writes only the cells of its own rectangle (layout gives every
  // instance its own, 2 × padding ≥ 2 texels apart) plus a one-texel margin for rounding, so no
  // cell is shared between tasks and each cell sees its triangles in the serial order. Each
  // instance rasterizes into an array of its own region only and keeps its live cells, so the
  // pages' cells are never all held as candidates (20 bytes each, 2.3 GB at 10 M texels).
  std::vector<std::vector<LiveCell>> instance_live(scene.instances.size());
  std::vector<size_t> overlapping_texels(scene.instances.size(), 0);
  // Each thread's region array is reused from instance to instance: a fresh one per instance
  // (1.4 GB in all on the open city) had the kernel fault in and zero every page first, half of
  // the stage's CPU time on the 2-core VM (its sys time).
  tbb::enumerable_thread_specific<std::vector<TexelCandidate>> region_cells;
  tbb::parallel_for(size_t(0), scene.instances.size(), [&](size_t i) {
    const Instance& instance = scene.instances[i];
    const InstanceRect& rect = layout.rects[i];
    AtlasPage& page = gbuffer.pages[size_t(rect.page)];
    const int rect_x0 = std::max(0, rect.x - 1), rect_y0 = std::max(0, rect.y - 1);
    const int rect_x1 = std::min(page.width - 1, rect.x + rect.width), rect_y1 = std::min(page.height - 1, rect.y + rect.height);
    if (rect_x1 < rect_x0 || rect_y1 < rect_y0) {
      done.add(instance.triangle_count);
      return;
    }
    const size_t region_width = size_t(rect_x1 - rect_x0 + 1);
    std::vector<TexelCandidate>& cells = region_cells.local();
    cells.assign(region_width * size_t(rect_y1 - rect_y0 + 1), TexelCandidate{});
    for (uint32_t t = instance.first_triangle; t < instance.first_triangle + instance.triangle_count; ++t) {
      Vec2 tri[3];
      chart_triangle_in_texels(scene, t, rect.scale_offset, page.width, page.height, tri);
      const Vec2 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
      const float texel_area = 0.5f * std::fabs(e1.x * e2.y - e1.y * e2.x);
      // The runtime's scene edits recompute it with the same function when an instance moves.
      triangle_texel_size[t] = triangle_world_texel_size(scene, t, rect, page.width, page.height);
      if (!(texel_area > 0)) continue;  // zero-area chart triangle: nothing to raster
      const int x0 = std::max(rect_x0, int(std::floor(std::min({tri[0].x, tri[1].x, tri[2].x}))));
      const int y0 = std::max(rect_y0, int(std::floor(std::min({tri[0].y, tri[1].y, tri[2].y}))));
      const int x1 = std::min(rect_x1, int(std::ceil(std::max({tri[0].x, tri[1].x, tri[2].x}))));
      const int y1 = std::min(rect_y1, int(std::ceil(std::max({tri[0].y, tri[1].y, tri[2].y}))));
      const CellRejection outside(tri);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          if (outside.rejects(x, y)) continue;  // clipped_texel_coverage would give it no area
          Vec2 centroid;
          const float area = clipped_texel_coverage(tri, x, y, centroid);
          // Slivers below 0.1 % of a texel are rounding noise of the UV transform; dilation covers them.
          if (area <= 1e-3f) continue;
          TexelCandidate& cell = cells[size_t(y - rect_y0) * region_width + size_t(x - rect_x0)];
          cell.coverage += area;
          if (area > cell.best_area) {
            cell.best_area = area;
            cell.triangle = t;
            cell.centroid = centroid;
          }
        }
    }
    instance_live[i].reserve(size_t(std::count_if(cells.begin(), cells.end(),
                                                  [](const TexelCandidate& c) { return c.best_area > 0; })));
    for (int y = rect_y0; y <= rect_y1; ++y)
      for (int x = rect_x0; x <= rect_x1; ++x) {
        const TexelCandidate& candidate = cells[size_t(y - rect_y0) * region_width + size_t(x - rect_x0)];
        if (candidate.best_area <= 0) continue;
        const uint32_t cell = uint32_t(y) * uint32_t(page.width) + uint32_t(x);
        instance_live[i].push_back({formats::texel_morton_code(uint32_t(x), uint32_t(y)), cell, candidate.triangle,
                                    candidate.centroid});
        if (candidate.coverage > 1.05f) ++overlapping_texels[i];
        page.coverage[cell] = std::min(1.0f, candidate.coverage);
      }
    done.add(instance.triangle_count);
  });
  // Each page's live cells in scene.bin's order (Morton codes are distinct within a page), pages
  // in parallel; then every texel filled in, in parallel.
  std::vector<std::vector<size_t>> page_instances(gbuffer.pages.size());
  for (size_t i = 0; i < scene.instances.size(); ++i) page_instances[size_t(layout.rects[i].page)].push_back(i);
  std::vector<std::vector<LiveCell>> live(gbuffer.pages.size());
  tbb::parallel_for(size_t(0), gbuffer.pages.size(), [&](size_t p) {
    size_t count = 0;
    for (size_t i : page_instances[p]) count += instance_live[i].size();
    live[p].reserve(count);
    for (size_t i : page_instances[p]) {
      live[p].insert(live[p].end(), instance_live[i].begin(), instance_live[i].end());
      std::vector<LiveCell>().swap(instance_live[i]);
    }
    std::sort(live[p].begin(), live[p].end(), [](const LiveCell& a, const LiveCell& b) { return a.morton < b.morton; });
  });
  std::vector<size_t> first_live(gbuffer.pages.size(), 0);
  size_t live_total = 0, cells_total = 0;
  for (size_t p = 0; p < gbuffer.pages.size(); ++p) {
    first_live[p] = live_total;
    live_total += live[p].size();
    cells_total += gbuffer.pages[p].coverage.size();
  }
  gbuffer.skipped_texels = cells_total - live_total;
  gbuffer.texels.resize(live_total);
  ParallelProgress filled(part(0.5, 0.5), live_total);
  tbb::parallel_for(size_t(0), gbuffer.pages.size(), [&](size_t p) {
    const AtlasPage& page = gbuffer.pages[p];
    tbb::parallel_for(tbb::blocked_range<size_t>(0, live[p].size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t k = range.begin(); k != range.end(); ++k) {
        const LiveCell& cell = live[p][k];
        const uint32_t x = cell.cell % uint32_t(page.width), y = cell.cell / uint32_t(page.width);
        const uint32_t t = cell.triangle;
        const uint32_t instance = scene.triangle_instance[t];
        const InstanceRect& rect = layout.rects[instance];
        // The texel's point is the centroid of its best triangle's part of it (texel_surface.h:
        // scene.bin's codec re-derives it from the triangle and the texel with the same calls).
        Vec2 tri[3];
        chart_triangle_in_texels(scene, t, rect.scale_offset, page.width, page.height, tri);
        float b1, b2;
        chart_barycentrics(tri, cell.centroid, b1, b2);
        const TexelSurface surface = texel_surface(scene, t, b1, b2);
        LiveTexel& texel = gbuffer.texels[first_live[p] + k];
        texel.page = uint32_t(p);
        texel.x = x;
        texel.y = y;
        texel.position = surface.position;
        texel.geometric_normal = surface.geometric_normal;
        texel.shading_normal = surface.shading_normal;
        texel.albedo = surface.albedo;
        texel.instance = instance;
        texel.triangle = t;
        texel.world_texel_size = triangle_texel_size[t];
      }
      filled.add(range.size());
    });
    std::vector<LiveCell>().swap(live[p]);  // done with this page: free it early
  });
  for (size_t i = 0; i < overlapping_texels.size(); ++i)
    if (overlapping_texels[i] > 0)
      diagnostics.warn(file + ": node " + std::to_string(scene.instances[i].node) + " (mesh " +
                       std::to_string(scene.instances[i].mesh) + "): lightmap UV charts overlap in " +
                       std::to_string(overlapping_texels[i]) + " texels");
  return gbuffer;
}

}  // namespace exitance
