#include "exitance/runtime/texel_surface.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/material_eval.h"

namespace exitance {

void chart_triangle_in_texels(const Scene& scene, uint32_t triangle, const float scale_offset[4], int page_width,
                              int page_height, Vec2 out[3]) {
  for (int k = 0; k < 3; ++k) {
    const Vec2 uv = scene.lightmap_uv[size_t(triangle) * 3 + size_t(k)];
    out[k] = {(uv.x * scale_offset[0] + scale_offset[2]) * float(page_width),
              (uv.y * scale_offset[1] + scale_offset[3]) * float(page_height)};
  }
}

float clipped_texel_coverage(const Vec2 triangle[3], int x, int y, Vec2& centroid) {
  // Sutherland-Hodgman: clip the texel square by the triangle's three edge half-planes.
  Vec2 polygon[9] = {
      {float(x), float(y)}, {float(x + 1), float(y)}, {float(x + 1), float(y + 1)}, {float(x), float(y + 1)}};
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

void chart_barycentrics(const Vec2 t[3], Vec2 p, float& b1, float& b2) {
  b1 = 1.0f / 3.0f;
  b2 = 1.0f / 3.0f;
  const Vec2 e1 = t[1] - t[0], e2 = t[2] - t[0], d = p - t[0];
  const double det = double(e1.x) * e2.y - double(e1.y) * e2.x;
  if (!(std::fabs(det) < 1e-20)) {
    b1 = float((double(d.x) * e2.y - double(d.y) * e2.x) / det);
    b2 = float((double(e1.x) * d.y - double(e1.y) * d.x) / det);
  }
  // The point lies inside the triangle up to rounding: clamp so it stays on it.
  b1 = std::clamp(b1, 0.0f, 1.0f);
  b2 = std::clamp(b2, 0.0f, 1.0f - b1);
}

void texel_barycentrics(const Scene& scene, const InstanceRect& rect, int page_width, int page_height, uint32_t t,
                        uint32_t x, uint32_t y, float& b1, float& b2) {
  Vec2 tri[3];
  chart_triangle_in_texels(scene, t, rect.scale_offset, page_width, page_height, tri);
  Vec2 centroid{float(x) + 0.5f, float(y) + 0.5f};  // kept when t does not cover the texel
  clipped_texel_coverage(tri, int(x), int(y), centroid);
  chart_barycentrics(tri, centroid, b1, b2);
}

float triangle_world_texel_size(const Scene& scene, uint32_t t, const InstanceRect& rect, int page_width,
                                int page_height) {
  Vec2 tri[3];
  chart_triangle_in_texels(scene, t, rect.scale_offset, page_width, page_height, tri);
  const Vec2 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
  const float texel_area = 0.5f * std::fabs(e1.x * e2.y - e1.y * e2.x);
  const float world_area = triangle_area(scene, t);
  return texel_area > 0 ? std::sqrt(world_area / texel_area) : 0.0f;
}

Vec3 texel_surface_position(const Scene& scene, uint32_t t, float b1, float b2) {
  const Vec3* pos = &scene.positions[size_t(t) * 3];
  return pos[0] * (1 - b1 - b2) + pos[1] * b1 + pos[2] * b2;
}

TexelSurface texel_surface(const Scene& scene, uint32_t t, float b1, float b2) {
  const Vec3* nrm = &scene.normals[size_t(t) * 3];
  TexelSurface s;
  s.position = texel_surface_position(scene, t, b1, b2);
  s.geometric_normal = triangle_normal(scene, t);
  Vec3 n = nrm[0] * (1 - b1 - b2) + nrm[1] * b1 + nrm[2] * b2;
  const float n_length = length(n);
  n = n_length > 0 ? n / n_length : s.geometric_normal;
  // Normals pointing into the back side would make the hemisphere sample the wrong side.
  s.shading_normal = dot(n, s.geometric_normal) > 0.05f ? n : s.geometric_normal;
  s.albedo = diffuse_albedo(scene, t, b1, b2);
  return s;
}

}  // namespace exitance
