// The compact texel G-buffer of scene.bin (formats/scene_format.md, "Texels") and back.
//
// A live texel is stored as its triangle, texel coordinates and barycentrics (b1, b2) on the
// triangle; world texel size per triangle; coverage 1 unless the texel is in the sparse
// `partial_coverage` table. Everything else is derived on decode with the rasterizer's own
// functions (texel_surface.h): position, geometric and shading normals and albedo from
// (triangle, b1, b2), instance from the triangle. The encoder takes (b1, b2) from the
// rasterizer's rule, not from the texel's position: the centroid of the part of texel (x, y) its
// triangle covers, in the chart the atlas rectangle places on the page (chart_triangle_in_texels,
// clipped_texel_coverage, chart_barycentrics). A texel whose position is not that point's (one
// the unocclude step moved) keeps its exact position in the sparse `moved` table.
//
// Hence, for a G-buffer the rasterizer (and unocclude) made:
//   decode(encode(g)) == g bit for bit: every texel field, page coverage and skipped_texels;
//   encode(decode(r)) == r, so decode(encode(.)) is idempotent bit for bit.
// A relight from scene.bin therefore starts from exactly the G-buffer the bake lit.
#pragma once
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// Throws formats::FormatError when the G-buffer cannot be stored: a page wider or taller than
// 65535 texels, a texel outside its page or on a missing triangle, live texels not page-major in
// Morton order, a live texel whose coverage is outside (0, 1] or a texel with coverage that is not
// live, texels of one triangle with different world texel sizes, or a texel whose instance,
// geometric normal, shading normal or albedo is not the one its triangle and the rasterizer's
// barycentrics give (only the position may differ: unocclude).
formats::TexelGBufferRecords encode_texel_gbuffer(const TexelGBuffer& gbuffer, const Scene& scene,
                                                  const AtlasLayout& atlas);

// Throws formats::FormatError when the records do not fit the scene (triangle, page or moved
// texel out of range); records that read_scene accepted together with the scene always fit.
TexelGBuffer decode_texel_gbuffer(const formats::TexelGBufferRecords& records, const Scene& scene);

}  // namespace exitance
