#include "exitance/bake/raster/texel_raster.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/material_eval.h"

namespace exitance {
namespace {

// Interleaves the bits of x and y (16 bits each) for Morton order.
uint32_t morton2(uint32_t x, uint32_t y) {
  auto spread = [](uint32_t v) {
    v &= 0xFFFF;
    v = (v | (v << 8)) & 0x00FF00FF;
    v = (v | (v << 4)) & 0x0F0F0F0F;
    v = (v | (v << 2)) & 0x33333333;
    v = (v | (v << 1)) & 0x55555555;
    return v;
  };
  return spread(x) | (spread(y) << 1);
}

struct TexelCandidate {
  float best_area = 0;
  float coverage = 0;
  uint32_t triangle = 0;
  Vec2 centroid;
};

// Barycentrics (b1, b2) of p in the 2D triangle.
bool barycentric_2d(const Vec2 t[3], Vec2 p, float& b1, float& b2) {
  const Vec2 e1 = t[1] - t[0], e2 = t[2] - t[0], d = p - t[0];
  const double det = double(e1.x) * e2.y - double(e1.y) * e2.x;
  if (std::fabs(det) < 1e-20) return false;
  b1 = float((double(d.x) * e2.y - double(d.y) * e2.x) / det);
  b2 = float((double(e1.x) * d.y - double(e1.y) * d.x) / det);
  return true;
}

}  // namespace

float clipped_texel_coverage(const Vec2 triangle[3], int x, int y, Vec2& centroid) {
  // Sutherland-Hodgman: clip the texel square by the triangle's three edge half-planes.
  Vec2 polygon[9] = {{float(x), float(y)}, {float(x + 1), float(y)}, {float(x + 1), float(y + 1)}, {float(x), float(y + 1)}};
  int count = 4;
  const Vec2 e1 = triangle[1] - triangle[0], e2 = triangle[2] - triangle[0];
  const float orientation = (e1.x * e2.y - e1.y * e2.x) >= 0 ? 1.0f : -1.0f;
  for (int edge = 0; edge < 3 && count > 0; ++edge) {
    const Vec2 a = triangle[edge], b = triangle[(edge + 1) % 3];
    auto side = [&](Vec2 p) { return orientation * ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)); };
    Vec2 out[9];
    int out_count = 0;
    for (int i = 0; i < count; ++i) {
      const Vec2 p = polygon[i], q = polygon[(i + 1) % count];
      const float sp = side(p), sq = side(q);
      if (sp >= 0) out[out_count++] = p;
      if ((sp >= 0) != (sq >= 0) && out_count < 9) {
        const float t = sp / (sp - sq);
        out[out_count++] = p + (q - p) * t;
      }
    }
    count = std::min(out_count, 9);
    std::copy(out, out + count, polygon);
  }
  if (count < 3) return 0.0f;
  double area2 = 0, cx = 0, cy = 0;
  for (int i = 0; i < count; ++i) {
    const Vec2 p = polygon[i], q = polygon[(i + 1) % count];
    const double c = double(p.x) * q.y - double(q.x) * p.y;
    area2 += c;
    cx += (double(p.x) + q.x) * c;
    cy += (double(p.y) + q.y) * c;
  }
  if (std::fabs(area2) < 1e-12) return 0.0f;
  centroid = {float(cx / (3.0 * area2)), float(cy / (3.0 * area2))};
  return float(std::fabs(area2) * 0.5);
}

TexelGBuffer rasterize_texel_gbuffer(const Scene& scene, const AtlasLayout& layout, const std::string& file,
                                     Diagnostics& diagnostics) {
  TexelGBuffer gbuffer;
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
      for (int k = 0; k < 3; ++k) {
        const Vec2 uv = scene.lightmap_uv[size_t(t) * 3 + size_t(k)];
        tri[k] = {(uv.x * rect.scale_offset[0] + rect.scale_offset[2]) * float(page.width),
                  (uv.y * rect.scale_offset[1] + rect.scale_offset[3]) * float(page.height)};
      }
      const Vec2 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
      const float texel_area = 0.5f * std::fabs(e1.x * e2.y - e1.y * e2.x);
      const float world_area = triangle_area(scene, t);
      triangle_texel_size[t] = texel_area > 0 ? std::sqrt(world_area / texel_area) : 0.0f;
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
        Vec2 tri[3];
        for (int k = 0; k < 3; ++k) {
          const Vec2 uv = scene.lightmap_uv[size_t(t) * 3 + size_t(k)];
          tri[k] = {(uv.x * rect.scale_offset[0] + rect.scale_offset[2]) * float(page.width),
                    (uv.y * rect.scale_offset[1] + rect.scale_offset[3]) * float(page.height)};
        }
        float b1 = 1.0f / 3.0f, b2 = 1.0f / 3.0f;
        barycentric_2d(tri, cell.centroid, b1, b2);
        // The centroid lies inside the triangle up to rounding: clamp so the point stays on it.
        b1 = std::clamp(b1, 0.0f, 1.0f);
        b2 = std::clamp(b2, 0.0f, 1.0f - b1);
        const Vec3* pos = &scene.positions[size_t(t) * 3];
        const Vec3* nrm = &scene.normals[size_t(t) * 3];
        LiveTexel texel;
        texel.page = uint32_t(p);
        texel.x = uint32_t(x);
        texel.y = uint32_t(y);
        texel.position = pos[0] * (1 - b1 - b2) + pos[1] * b1 + pos[2] * b2;
        texel.geometric_normal = triangle_normal(scene, t);
        Vec3 n = nrm[0] * (1 - b1 - b2) + nrm[1] * b1 + nrm[2] * b2;
        const float n_length = length(n);
        n = n_length > 0 ? n / n_length : texel.geometric_normal;
        // Normals pointing into the back side would make the hemisphere sample the wrong side.
        texel.shading_normal = dot(n, texel.geometric_normal) > 0.05f ? n : texel.geometric_normal;
        texel.albedo = diffuse_albedo(scene, t, b1, b2);
        texel.instance = instance;
        texel.triangle = t;
        texel.world_texel_size = triangle_texel_size[t];
        gbuffer.texels.push_back(texel);
      }
    std::sort(gbuffer.texels.begin() + long(first_live), gbuffer.texels.end(),
              [](const LiveTexel& a, const LiveTexel& b) { return morton2(a.x, a.y) < morton2(b.x, b.y); });
  }
  for (size_t i = 0; i < overlapping_texels.size(); ++i)
    if (overlapping_texels[i] > 0)
      diagnostics.warn(file + ": node " + std::to_string(scene.instances[i].node) + " (mesh " +
                       std::to_string(scene.instances[i].mesh) + "): lightmap UV charts overlap in " +
                       std::to_string(overlapping_texels[i]) + " texels");
  return gbuffer;
}

}  // namespace exitance
