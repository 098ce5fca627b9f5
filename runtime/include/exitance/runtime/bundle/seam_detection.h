// Lightmap UV seams (issue 13, "Seams"): mesh edges that are one edge in 3-D but two edges in the
// atlas, so the texels on either side are lit separately and a bilinear lookup shows the cut as a
// line. seam_stitching.h makes the two sides agree.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct SeamDetectionSettings {
  // Corners closer than this fraction of the instance's bounding-box diagonal are one 3-D point.
  float weld_tolerance = 1e-5f;
  // A seam is stitched only where the corner shading normals of both sides agree within this angle
  // at both ends. A hard edge (a cube's 90°) is meant to show a crease and is left alone; 10° is
  // above the float noise of normals that glTF exporters split along a UV cut (they are equal) and
  // well below the facets of low-poly flat-shaded meshes (a 16-sided cylinder's are 22.5°).
  float max_normal_angle_degrees = 10.0f;
  // The two sides' atlas edges closer than this (texels, at both ends) are one edge: no seam.
  float same_uv_tolerance_texels = 1e-3f;
};

// One seam edge in atlas texel coordinates (page_uv * page size, as texel_raster.cpp rasterizes:
// texel (x, y) covers [x, x+1] x [y, y+1]). side_a[k] and side_b[k] are the same 3-D point.
struct SeamEdge {
  uint32_t instance = 0;
  int page = 0;
  Vec2 side_a[2];
  Vec2 side_b[2];
};

// The seams of every instance, each instance through its atlas rectangle's scale_offset. Edges
// shared by more than two triangles (non-manifold) are skipped: which pairs to join is ambiguous.
std::vector<SeamEdge> find_lightmap_seams(const Scene& scene, const AtlasLayout& layout,
                                          const SeamDetectionSettings& settings = {});

}  // namespace exitance
