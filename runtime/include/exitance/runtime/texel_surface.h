// Where a live texel lies on its triangle and the surface attributes there: the chart geometry
// and formulas of the texel rasterizer (bake/raster/texel_raster.cpp), in one compiled copy that the
// rasterizer and the scene.bin G-buffer codec (texel_gbuffer_codec.h) both call, so the codec
// re-derives a texel bit for bit from (triangle, x, y) and the atlas rectangle.
#pragma once
#include <cstdint>

#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/scene.h"

namespace exitance {

// Triangle t's lightmap UVs in texel units of a page_width x page_height page:
// (uv * scale_offset[0..1] + scale_offset[2..3]) * page size.
void chart_triangle_in_texels(const Scene& scene, uint32_t triangle, const float scale_offset[4], int page_width,
                              int page_height, Vec2 out[3]);

// Area of the part of the unit texel square [x,x+1]x[y,y+1] inside the triangle (any winding),
// and the centroid of that part (left unchanged when the area is 0).
float clipped_texel_coverage(const Vec2 triangle[3], int x, int y, Vec2& centroid);

// Barycentrics (b1, b2) of `point` in the 2D triangle, clamped onto it (b1 in [0, 1], b2 in
// [0, 1 - b1]); (1/3, 1/3) when the triangle is degenerate.
void chart_barycentrics(const Vec2 triangle[3], Vec2 point, float& b1, float& b2);

// The rasterizer's barycentrics of texel (x, y) on triangle t of the instance `rect` places on a
// page_width x page_height page: the centroid of the part of the texel the chart triangle covers
// (the texel centre when it covers none), by chart_barycentrics.
void texel_barycentrics(const Scene& scene, const InstanceRect& rect, int page_width, int page_height, uint32_t t,
                        uint32_t x, uint32_t y, float& b1, float& b2);

// World-space edge length of one texel on triangle t: sqrt(world area / chart area in texels);
// 0 when the chart triangle has no area (it has no texels).
float triangle_world_texel_size(const Scene& scene, uint32_t t, const InstanceRect& rect, int page_width,
                                int page_height);

// What a texel at barycentrics (b1, b2) of `triangle` sees:
//   position         = p0 (1 - b1 - b2) + p1 b1 + p2 b2
//   geometric_normal = triangle_normal(scene, triangle)
//   shading_normal   = the interpolated vertex normal, normalized; the geometric normal when it
//                      is zero or leans to the back side (dot <= 0.05)
//   albedo           = diffuse_albedo(scene, triangle, b1, b2)
struct TexelSurface {
  Vec3 position, geometric_normal, shading_normal, albedo;
};
TexelSurface texel_surface(const Scene& scene, uint32_t triangle, float b1, float b2);
// texel_surface's position alone, the same bits (an edit's tests of where texels lie need no albedo).
Vec3 texel_surface_position(const Scene& scene, uint32_t triangle, float b1, float b2);

}  // namespace exitance
