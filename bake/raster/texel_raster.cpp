#include "exitance/bake/raster/texel_raster.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

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
  // Pages are mostly empty at scale (a 10 M-texel atlas holds ~100 M cells): clearing them is a
  // large part of the stage, so it runs in parallel too.
  std::vector<std::vector<TexelCandidate>> candidates(gbuffer.pages.size());
  tbb::parallel_for(size_t(0), gbuffer.pages.size(), [&](size_t p) {
    const size_t cells = size_t(gbuffer.pages[p].width) * size_t(gbuffer.pages[p].height);
    gbuffer.pages[p].coverage.assign(cells, 0.0f);
    candidates[p].resize(cells);
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
  // cell is shared between tasks and each cell sees its triangles in the serial order.
  tbb::parallel_for(size_t(0), scene.instances.size(), [&](size_t i) {
    const Instance& instance = scene.instances[i];
    const InstanceRect& rect = layout.rects[i];
    const AtlasPage& page = gbuffer.pages[size_t(rect.page)];
    std::vector<TexelCandidate>& cells = candidates[size_t(rect.page)];
    const int rect_x0 = std::max(0, rect.x - 1), rect_y0 = std::max(0, rect.y - 1);
    const int rect_x1 = std::min(page.width - 1, rect.x + rect.width), rect_y1 = std::min(page.height - 1, rect.y + rect.height);
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
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          Vec2 centroid;
          const float area = clipped_texel_coverage(tri, x, y, centroid);
          // Slivers below 0.1 % of a texel are rounding noise of the UV transform; dilation covers them.
          if (area <= 1e-3f) continue;
          TexelCandidate& cell = cells[size_t(y) * size_t(page.width) + size_t(x)];
          cell.coverage += area;
          if (area > cell.best_area) {
            cell.best_area = area;
            cell.triangle = t;
            cell.centroid = centroid;
          }
        }
    }
    done.add(instance.triangle_count);
  });
  // Each page's live cells in scene.bin's order (Morton codes are distinct within a page), pages
  // in parallel; then every texel filled in, in parallel.
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> live(gbuffer.pages.size());  // (Morton code, cell)
  std::vector<std::vector<size_t>> page_overlaps(gbuffer.pages.size());
  std::vector<size_t> page_skipped(gbuffer.pages.size(), 0);
  tbb::parallel_for(size_t(0), gbuffer.pages.size(), [&](size_t p) {
    AtlasPage& page = gbuffer.pages[p];
    const std::vector<TexelCandidate>& page_cells = candidates[p];
    page_overlaps[p].assign(scene.instances.size(), 0);
    for (int y = 0; y < page.height; ++y)
      for (int x = 0; x < page.width; ++x) {
        const uint32_t cell = uint32_t(y) * uint32_t(page.width) + uint32_t(x);
        const TexelCandidate& candidate = page_cells[cell];
        if (candidate.best_area <= 0) {
          ++page_skipped[p];
          continue;
        }
        live[p].push_back({formats::texel_morton_code(uint32_t(x), uint32_t(y)), cell});
        if (candidate.coverage > 1.05f) ++page_overlaps[p][scene.triangle_instance[candidate.triangle]];
        page.coverage[cell] = std::min(1.0f, candidate.coverage);
      }
    std::sort(live[p].begin(), live[p].end());
  });
  std::vector<size_t> overlapping_texels(scene.instances.size(), 0);
  std::vector<size_t> first_live(gbuffer.pages.size(), 0);
  size_t live_total = 0;
  for (size_t p = 0; p < gbuffer.pages.size(); ++p) {
    gbuffer.skipped_texels += page_skipped[p];
    for (size_t i = 0; i < overlapping_texels.size(); ++i) overlapping_texels[i] += page_overlaps[p][i];
    first_live[p] = live_total;
    live_total += live[p].size();
  }
  gbuffer.texels.resize(live_total);
  ParallelProgress filled(part(0.5, 0.5), live_total);
  tbb::parallel_for(size_t(0), gbuffer.pages.size(), [&](size_t p) {
    const AtlasPage& page = gbuffer.pages[p];
    const std::vector<TexelCandidate>& page_cells = candidates[p];
    tbb::parallel_for(tbb::blocked_range<size_t>(0, live[p].size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t k = range.begin(); k != range.end(); ++k) {
        const uint32_t cell_index = live[p][k].second;
        const TexelCandidate& cell = page_cells[cell_index];
        const uint32_t x = cell_index % uint32_t(page.width), y = cell_index / uint32_t(page.width);
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
    std::vector<TexelCandidate>().swap(candidates[p]);  // done with this page: free it early
  });
  for (size_t i = 0; i < overlapping_texels.size(); ++i)
    if (overlapping_texels[i] > 0)
      diagnostics.warn(file + ": node " + std::to_string(scene.instances[i].node) + " (mesh " +
                       std::to_string(scene.instances[i].mesh) + "): lightmap UV charts overlap in " +
                       std::to_string(overlapping_texels[i]) + " texels");
  return gbuffer;
}

}  // namespace exitance
