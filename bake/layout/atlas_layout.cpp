#include "exitance/bake/layout/atlas_layout.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "exitance/bake/input_error.h"

namespace exitance {
namespace {

struct InstanceMeasure {
  double world_area = 0;
  double uv_area = 0;
  Vec2 uv_min{1e30f, 1e30f}, uv_max{-1e30f, -1e30f};
};

std::vector<InstanceMeasure> measure_instances(const Scene& scene) {
  std::vector<InstanceMeasure> measures(scene.instances.size());
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    InstanceMeasure& m = measures[i];
    for (uint32_t t = instance.first_triangle; t < instance.first_triangle + instance.triangle_count; ++t) {
      const Vec2* uv = &scene.lightmap_uv[size_t(t) * 3];
      m.world_area += triangle_area(scene, t);
      const Vec2 e1 = uv[1] - uv[0], e2 = uv[2] - uv[0];
      m.uv_area += 0.5 * std::fabs(double(e1.x) * e2.y - double(e1.y) * e2.x);
      for (int k = 0; k < 3; ++k) {
        m.uv_min = {std::min(m.uv_min.x, uv[k].x), std::min(m.uv_min.y, uv[k].y)};
        m.uv_max = {std::max(m.uv_max.x, uv[k].x), std::max(m.uv_max.y, uv[k].y)};
      }
    }
  }
  return measures;
}

}  // namespace

float automatic_texel_density(const Scene& scene, size_t max_total_texels) {
  double area = 0;
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    area += triangle_area(scene, t);
  }
  const double preferred = 64.0;
  // Charts fill roughly half their rectangles; keep the texel total under the budget.
  const double budget_density = std::sqrt(double(max_total_texels) * 0.5 / std::max(area, 1e-12));
  return float(std::min(preferred, budget_density));
}

AtlasLayout layout_lightmap_atlas(const Scene& scene, const AtlasSettings& settings, const std::string& file,
                                  Diagnostics& diagnostics) {
  AtlasLayout layout;
  layout.texel_density =
      settings.texel_density > 0 ? settings.texel_density : automatic_texel_density(scene, settings.max_total_texels);
  const std::vector<InstanceMeasure> measures = measure_instances(scene);
  const int usable = settings.max_page - 2 * settings.padding;
  if (usable < 4) throw InputError(file, "--max-page", "is too small for the padding");

  std::vector<int> widths(measures.size()), heights(measures.size());
  for (size_t i = 0; i < measures.size(); ++i) {
    const InstanceMeasure& m = measures[i];
    const Instance& instance = scene.instances[i];
    if (!(m.uv_area > 1e-14))
      throw InputError(file, "node " + std::to_string(instance.node),
                       "lightmap UVs of mesh " + std::to_string(instance.mesh) + " have zero area");
    // Texels per UV unit so that texels per world unit equals the density on average.
    double texels_per_uv = double(layout.texel_density) * std::sqrt(m.world_area / m.uv_area);
    double w = double(m.uv_max.x - m.uv_min.x) * texels_per_uv, h = double(m.uv_max.y - m.uv_min.y) * texels_per_uv;
    const double largest = std::max(w, h);
    if (largest > usable) {
      w *= usable / largest;
      h *= usable / largest;
      ++layout.capped_instances;
    }
    widths[i] = std::clamp(int(std::ceil(w)), 2, usable);
    heights[i] = std::clamp(int(std::ceil(h)), 2, usable);
  }
  if (layout.capped_instances)
    diagnostics.warn(file + ": " + std::to_string(layout.capped_instances) +
                     " instances were shrunk to fit --max-page " + std::to_string(settings.max_page));

  // Page width: about square for the total area, never above max_page.
  double total_area = 0;
  for (size_t i = 0; i < widths.size(); ++i)
    total_area += double(widths[i] + 2 * settings.padding) * double(heights[i] + 2 * settings.padding);
  int page_width = int(std::ceil(std::sqrt(total_area * 1.15)));
  for (size_t i = 0; i < widths.size(); ++i) page_width = std::max(page_width, widths[i] + 2 * settings.padding);
  page_width = std::min(settings.max_page, (page_width + 3) / 4 * 4);

  std::vector<size_t> order(widths.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return heights[a] > heights[b]; });

  layout.rects.resize(widths.size());
  int page = 0, cursor_x = 0, shelf_y = 0, shelf_height = 0;
  std::vector<int> page_heights{0};
  for (size_t i : order) {
    const int w = widths[i] + 2 * settings.padding, h = heights[i] + 2 * settings.padding;
    if (cursor_x + w > page_width) {  // next shelf
      shelf_y += shelf_height;
      cursor_x = 0;
      shelf_height = 0;
    }
    if (shelf_y + h > settings.max_page) {  // next page
      ++page;
      page_heights.push_back(0);
      cursor_x = shelf_y = shelf_height = 0;
    }
    InstanceRect& r = layout.rects[i];
    r.page = page;
    r.x = cursor_x + settings.padding;
    r.y = shelf_y + settings.padding;
    r.width = widths[i];
    r.height = heights[i];
    cursor_x += w;
    shelf_height = std::max(shelf_height, h);
    page_heights[size_t(page)] = std::max(page_heights[size_t(page)], shelf_y + h);
  }
  for (int height : page_heights) layout.page_sizes.push_back({page_width, (height + 3) / 4 * 4});

  // page_uv = uv * s + o maps the instance's UV bounding box onto its rectangle.
  for (size_t i = 0; i < layout.rects.size(); ++i) {
    InstanceRect& r = layout.rects[i];
    const InstanceMeasure& m = measures[i];
    const auto [pw, ph] = layout.page_sizes[size_t(r.page)];
    const double du = std::max(1e-12, double(m.uv_max.x - m.uv_min.x));
    const double dv = std::max(1e-12, double(m.uv_max.y - m.uv_min.y));
    const double sx = double(r.width) / (du * pw), sy = double(r.height) / (dv * ph);
    r.scale_offset[0] = float(sx);
    r.scale_offset[1] = float(sy);
    r.scale_offset[2] = float(double(r.x) / pw - m.uv_min.x * sx);
    r.scale_offset[3] = float(double(r.y) / ph - m.uv_min.y * sy);
  }
  return layout;
}

}  // namespace exitance
