// Lightmap UVs for a mesh that has none (issue 13): charts grown by normal cone on the position-welded
// mesh, each flattened by LSCM (CGAL) or, when that fails, projected onto its plane, scaled to a
// uniform texel density and packed into the unit square with a gutter measured in texels. Small
// curved meshes try a few other layouts (other first seeds, arches halved) and keep the tightest.
//
// Why the texel density is an input: a gutter is only meaningful at a resolution. The atlas layout
// (bake/layout/atlas_layout.cpp) gives an instance texels_per_uv = density * sqrt(world area / UV
// area). Charts packed here at `texels_per_unit` texels per mesh-local unit, into a W x H texel
// rectangle normalized by S = max(W, H), have UV area = local area * texels_per_unit^2 / S^2, so the
// layout gives an instance whose world area is A_w texels_per_uv = S * density * sqrt(A_w / A_local)
// / texels_per_unit. With texels_per_unit = density * min over instances sqrt(A_w / A_local) (what
// generate_missing_lightmap_uvs passes), every instance gets at least S texels per UV unit, so the
// gutter packed in texels here is at least as wide at every rectangle the layout lays out; the
// packing also stays within the layout's page (max_side_texels) so the layout never shrinks it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "exitance/runtime/vec_math.h"

namespace exitance {

struct UvGenerationSettings {
  double texels_per_unit = 32;       // texels per mesh-local unit at the smallest instance
  int max_side_texels = 2044;        // the packed rectangle's sides never exceed this
  // Gap between charts. A gap of 3 texels keeps 2 whole texels free between conservatively
  // rasterized charts; the extra 0.1 absorbs float rounding of the UVs and of the layout's area sums.
  double gutter_texels = 3.1;
  double chart_cone_degrees = 90;    // a chart's faces stay within this angle of its seed's normal (measured:
                                     // 2 charts on a UV sphere, 5 on a torus before the layout search; 66 gave 7 and 16)
  double sharp_edge_degrees = 75;    // faces meeting at a larger dihedral angle are never one chart
  size_t max_chart_triangles = 20000;  // larger charts are split (bounds LSCM's solve)
  // Meshes up to this many triangles search for a tighter layout (up to 9 packings): charts also
  // grown from the faces whose normals point farthest along +-x, +-y, +-z, then up to split_charts
  // times the largest chart filling less than split_below_fill of its bounding box halved across
  // its long axis; the layout whose charts fill most of the packed rectangle is kept.
  size_t layout_search_max_triangles = 50000;
  int split_charts = 2;
  double split_below_fill = 0.6;
  double stretch_bound = 2;          // a chart whose mean area or angle distortion exceeds it is "stretched"
  std::function<void(double)> progress;  // fraction done, called from the calling thread
};

struct UvGenerationStats {
  size_t triangles = 0;
  size_t charts = 0;
  size_t lscm_charts = 0;            // flattened by LSCM
  size_t planar_charts = 0;          // LSCM refused or failed: projected onto the chart's plane
  size_t degenerate_triangles = 0;   // zero area: folded into a neighbouring chart or a point chart
  size_t stretched_charts = 0;       // beyond UvGenerationSettings::stretch_bound
  double utilization = 0;            // chart area / packed rectangle area
  // Per triangle, from the singular values s1 >= s2 of the 3-D → UV map normalized so UV area equals
  // 3-D area over the mesh: area distortion max(s1 s2, 1/(s1 s2)), angle distortion s1/s2 (1 = none).
  double max_area_distortion = 1, mean_area_distortion = 1;  // mean weighted by 3-D area
  double max_angle_distortion = 1, mean_angle_distortion = 1;
  int packed_width = 0, packed_height = 0;  // texels at texels_per_unit
  double texels_per_unit = 0;        // the density packed at (lower than asked if the page was too small)
  bool gutter_holds = true;          // false: even the smallest scale did not fit max_side_texels
};

struct GeneratedUvs {
  std::vector<Vec2> corner_uv;          // 3 per input triangle, in [0,1]^2, all finite
  std::vector<uint32_t> triangle_chart;  // the chart of each input triangle
  UvGenerationStats stats;
};

// `indices` holds 3 vertex indices per triangle into `positions` (mesh-local). Deterministic: the
// same input gives the same UVs bit for bit. Throws std::invalid_argument for an index out of range.
GeneratedUvs generate_lightmap_uvs(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                   const UvGenerationSettings& settings);

}  // namespace exitance
