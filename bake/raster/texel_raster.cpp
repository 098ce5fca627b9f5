#include "exitance/bake/raster/texel_raster.h"

#include <algorithm>
#include <cmath>

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
                                     Diagnostics& diagnostics) {
  TexelGBuffer gbuffer;
  gbuffer.instance_rects = layout.rects;
  std::vector<std::vector<TexelCandidate>> candidates;
  for (const auto& [w, h] : layout.page_sizes) {
    AtlasPage page;
    page.width = w;
    page.height = h;
    page.coverage.assign(size_t(w) * size_t(h), 0.0f);
    gbuffer.pages.push_back(std::move(page));
    candidates.emplace_back(size_t(w) * size_t(h));
  }
  std::vector<float> triangle_texel_size(scene.triangle_count(), 0.0f);
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    const InstanceRect& rect = layout.rects[i];
    AtlasPage& page = gbuffer.pages[size_t(rect.page)];
    std::vector<TexelCandidate>& cells = candidates[size_t(rect.page)];
    for (uint32_t t = instance.first_triangle; t < instance.first_triangle + instance.triangle_count; ++t) {
      Vec2 tri[3];
      chart_triangle_in_texels(scene, t, rect.scale_offset, page.width, page.height, tri);
      const Vec2 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
      const float texel_area = 0.5f * std::fabs(e1.x * e2.y - e1.y * e2.x);
      // The runtime's scene edits recompute it with the same function when an instance moves.
      triangle_texel_size[t] = triangle_world_texel_size(scene, t, rect, page.width, page.height);
      if (!(texel_area > 0)) continue;  // zero-area chart triangle: nothing to raster
      const int x0 = std::max(0, int(std::floor(std::min({tri[0].x, tri[1].x, tri[2].x}))));
      const int y0 = std::max(0, int(std::floor(std::min({tri[0].y, tri[1].y, tri[2].y}))));
      const int x1 = std::min(page.width - 1, int(std::ceil(std::max({tri[0].x, tri[1].x, tri[2].x}))));
      const int y1 = std::min(page.height - 1, int(std::ceil(std::max({tri[0].y, tri[1].y, tri[2].y}))));
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
  }
  std::vector<size_t> overlapping_texels(scene.instances.size(), 0);
  for (size_t p = 0; p < gbuffer.pages.size(); ++p) {
    AtlasPage& page = gbuffer.pages[p];
    const size_t first_live = gbuffer.texels.size();
    for (int y = 0; y < page.height; ++y)
      for (int x = 0; x < page.width; ++x) {
        const TexelCandidate& cell = candidates[p][size_t(y) * size_t(page.width) + size_t(x)];
        if (cell.best_area <= 0) {
          ++gbuffer.skipped_texels;
          continue;
        }
        const uint32_t t = cell.triangle;
        const uint32_t instance = scene.triangle_instance[t];
        if (cell.coverage > 1.05f) ++overlapping_texels[instance];
        page.coverage[size_t(y) * size_t(page.width) + size_t(x)] = std::min(1.0f, cell.coverage);
        const InstanceRect& rect = layout.rects[instance];
        // The texel's point is the centroid of its best triangle's part of it (texel_surface.h:
        // scene.bin's codec re-derives it from the triangle and the texel with the same calls).
        Vec2 tri[3];
        chart_triangle_in_texels(scene, t, rect.scale_offset, page.width, page.height, tri);
        float b1, b2;
        chart_barycentrics(tri, cell.centroid, b1, b2);
        const TexelSurface surface = texel_surface(scene, t, b1, b2);
        LiveTexel texel;
        texel.page = uint32_t(p);
        texel.x = uint32_t(x);
        texel.y = uint32_t(y);
        texel.position = surface.position;
        texel.geometric_normal = surface.geometric_normal;
        texel.shading_normal = surface.shading_normal;
        texel.albedo = surface.albedo;
        texel.instance = instance;
        texel.triangle = t;
        texel.world_texel_size = triangle_texel_size[t];
        gbuffer.texels.push_back(texel);
      }
    std::sort(gbuffer.texels.begin() + long(first_live), gbuffer.texels.end(),
              [](const LiveTexel& a, const LiveTexel& b) { return formats::texel_morton_code(a.x, a.y) < formats::texel_morton_code(b.x, b.y); });
  }
  for (size_t i = 0; i < overlapping_texels.size(); ++i)
    if (overlapping_texels[i] > 0)
      diagnostics.warn(file + ": node " + std::to_string(scene.instances[i].node) + " (mesh " +
                       std::to_string(scene.instances[i].mesh) + "): lightmap UV charts overlap in " +
                       std::to_string(overlapping_texels[i]) + " texels");
  return gbuffer;
}

}  // namespace exitance
