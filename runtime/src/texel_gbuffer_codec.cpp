#include "exitance/runtime/texel_gbuffer_codec.h"

#include <atomic>
#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/texel_surface.h"

namespace exitance {
namespace {

using formats::FormatError;

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

std::string texel_where(size_t i) { return "scene.bin (writing): texel " + std::to_string(i) + ": "; }

// What a texel's triangle gives at the texel, derived in parallel before the ordered pass that
// checks and stores the texels (it throws at the first bad texel, as a serial loop would). Left
// at its defaults where the texel's page, cell, triangle or instance is invalid: that pass throws
// before it reads them.
struct DerivedTexel {
  float b1 = 0, b2 = 0;
  bool geometric_normal_differs = false, shading_differs = false, moved = false;
};

}  // namespace

formats::TexelGBufferRecords encode_texel_gbuffer(const TexelGBuffer& gbuffer, const Scene& scene,
                                                  const AtlasLayout& atlas) {
  if (atlas.rects.size() != scene.instances.size())
    throw FormatError("scene.bin (writing): the atlas has " + std::to_string(atlas.rects.size()) + " rectangles for " +
                      std::to_string(scene.instances.size()) + " instances");
  formats::TexelGBufferRecords records;
  for (size_t p = 0; p < gbuffer.pages.size(); ++p) {
    const AtlasPage& page = gbuffer.pages[p];
    if (page.width <= 0 || page.height <= 0 || page.width > int(formats::kMaxScenePageSize) ||
        page.height > int(formats::kMaxScenePageSize))
      throw FormatError("scene.bin (writing): page " + std::to_string(p) + ": size " + std::to_string(page.width) +
                        " x " + std::to_string(page.height) + " is not within 1 .. " +
                        std::to_string(formats::kMaxScenePageSize) + " (texel x and y are stored as u16)");
    if (page.coverage.size() != size_t(page.width) * size_t(page.height))
      throw FormatError("scene.bin (writing): page " + std::to_string(p) + ": coverage has " +
                        std::to_string(page.coverage.size()) + " entries for " + std::to_string(page.width) + " x " +
                        std::to_string(page.height) + " texels");
    records.pages.push_back({uint32_t(page.width), uint32_t(page.height), 0});
  }
  // Coverage is stored for live texels only: mark them; every other texel must be uncovered.
  std::vector<std::vector<uint8_t>> live(gbuffer.pages.size());
  for (size_t p = 0; p < gbuffer.pages.size(); ++p) live[p].assign(gbuffer.pages[p].coverage.size(), 0);

  records.texels.reserve(gbuffer.texels.size());
  // World texel size is per triangle (the rasterizer's): the first texel of a triangle sets it.
  records.triangle_texel_size.assign(scene.triangle_count(), 0.0f);
  std::vector<uint8_t> size_set(scene.triangle_count(), 0);
  // Re-deriving each texel's surface is the bulk of the work at 10 M texels: done in parallel
  // (for_each_chunk bodies must not throw: a texel that cannot be derived is left for the
  // ordered pass to report).
  std::vector<DerivedTexel> derived(gbuffer.texels.size());
  for_each_chunk(gbuffer.texels.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const LiveTexel& texel = gbuffer.texels[i];
      if (texel.page >= gbuffer.pages.size() || texel.triangle >= scene.triangle_count()) continue;
      const AtlasPage& page = gbuffer.pages[texel.page];
      if (texel.x >= uint32_t(page.width) || texel.y >= uint32_t(page.height)) continue;
      const uint32_t instance = scene.triangle_instance[texel.triangle];
      if (texel.instance != instance || instance >= atlas.rects.size() || atlas.rects[instance].page != int(texel.page))
        continue;
      DerivedTexel& d = derived[i];
      texel_barycentrics(scene, atlas.rects[instance], page.width, page.height, texel.triangle, texel.x, texel.y, d.b1,
                         d.b2);
      const TexelSurface surface = texel_surface(scene, texel.triangle, d.b1, d.b2);
      d.geometric_normal_differs = !same_bits(surface.geometric_normal, texel.geometric_normal);
      d.shading_differs = !same_bits(surface.shading_normal, texel.shading_normal) || !same_bits(surface.albedo, texel.albedo);
      d.moved = !same_bits(surface.position, texel.position);
    }
  });
  uint32_t previous_page = 0;
  uint64_t previous_code = 0;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& texel = gbuffer.texels[i];
    if (texel.page >= gbuffer.pages.size())
      throw FormatError(texel_where(i) + "page " + std::to_string(texel.page) + " does not exist");
    const AtlasPage& page = gbuffer.pages[texel.page];
    if (texel.x >= uint32_t(page.width) || texel.y >= uint32_t(page.height))
      throw FormatError(texel_where(i) + "(" + std::to_string(texel.x) + ", " + std::to_string(texel.y) +
                        ") lies outside its page");
    if (texel.page < previous_page) throw FormatError(texel_where(i) + "live texels are not page-major");
    if (texel.page != previous_page) previous_code = 0;
    const uint64_t code = uint64_t(formats::texel_morton_code(texel.x, texel.y)) + 1;
    if (code <= previous_code) throw FormatError(texel_where(i) + "live texels of a page are not in Morton order");
    previous_page = texel.page;
    previous_code = code;
    if (texel.triangle >= scene.triangle_count())
      throw FormatError(texel_where(i) + "triangle " + std::to_string(texel.triangle) + " does not exist");
    const uint32_t instance = scene.triangle_instance[texel.triangle];
    if (texel.instance != instance)
      throw FormatError(texel_where(i) + "instance " + std::to_string(texel.instance) + " is not its triangle's");
    if (instance >= atlas.rects.size() || atlas.rects[instance].page != int(texel.page))
      throw FormatError(texel_where(i) + "its triangle's instance is not on page " + std::to_string(texel.page));
    const size_t at = size_t(texel.y) * size_t(page.width) + texel.x;
    const float coverage = page.coverage[at];
    if (!(coverage > 0 && coverage <= 1))
      throw FormatError(texel_where(i) + "coverage " + std::to_string(coverage) + " is not in (0, 1]");
    live[texel.page][at] = 1;

    formats::TexelRecord r;
    r.triangle = texel.triangle;
    r.x = uint16_t(texel.x);
    r.y = uint16_t(texel.y);
    float& triangle_size = records.triangle_texel_size[texel.triangle];
    if (!size_set[texel.triangle]) {
      triangle_size = texel.world_texel_size;
      size_set[texel.triangle] = 1;
    } else if (std::bit_cast<uint32_t>(triangle_size) != std::bit_cast<uint32_t>(texel.world_texel_size)) {
      throw FormatError(texel_where(i) + "world texel size differs from that of other texels of triangle " +
                        std::to_string(texel.triangle));
    }
    if (coverage != 1.0f) records.partial_coverage.push_back({uint32_t(i), coverage});
    const DerivedTexel& d = derived[i];  // derived: every check above passed
    r.b1 = d.b1, r.b2 = d.b2;
    if (d.geometric_normal_differs) throw FormatError(texel_where(i) + "geometric normal is not its triangle's");
    if (d.shading_differs)
      throw FormatError(texel_where(i) +
                        "shading normal or albedo is not what its triangle gives at the texel "
                        "(scene.bin derives them; is this G-buffer the rasterizer's?)");
    if (d.moved)
      records.moved.push_back({uint32_t(i), {texel.position.x, texel.position.y, texel.position.z}});
    records.texels.push_back(r);
    ++records.pages[texel.page].live_texels;
  }
  for (size_t p = 0; p < gbuffer.pages.size(); ++p) {
    // Pages are mostly empty cells at scale: find a covered cell that is not live in parallel.
    const std::vector<float>& coverage = gbuffer.pages[p].coverage;
    std::atomic<size_t> first_stray{live[p].size()};
    for_each_chunk(live[p].size(), [&](size_t begin, size_t end) {
      for (size_t k = begin; k < end; ++k)
        if (!live[p][k] && coverage[k] != 0.0f) {
          size_t seen = first_stray.load();
          while (k < seen && !first_stray.compare_exchange_weak(seen, k)) {
          }
          break;
        }
    });
    const size_t k = first_stray.load();
    if (k < live[p].size())
      throw FormatError("scene.bin (writing): page " + std::to_string(p) + ": texel (" +
                        std::to_string(k % size_t(gbuffer.pages[p].width)) + ", " +
                        std::to_string(k / size_t(gbuffer.pages[p].width)) + ") has coverage but is not live");
  }
  return records;
}

TexelGBuffer decode_texel_gbuffer(const formats::TexelGBufferRecords& records, const Scene& scene) {
  TexelGBuffer gbuffer;
  size_t area = 0;
  for (const formats::TexelPageRecord& p : records.pages) {
    AtlasPage page;
    page.width = int(p.width);
    page.height = int(p.height);
    formats::resize_in_huge_pages(page.coverage, size_t(p.width) * size_t(p.height));  // zeros
    area += page.coverage.size();
    gbuffer.pages.push_back(std::move(page));
  }
  formats::resize_in_huge_pages(gbuffer.texels, records.texels.size());  // its first touch was most of a decode
  if (records.triangle_texel_size.size() != scene.triangle_count())
    throw FormatError("scene.bin: world texel sizes do not match the triangles");
  // Checked and placed in file order (the moved and partial tables ascend with the texels), then
  // each texel's surface derived on all cores, then the moved positions put back over it.
  size_t index = 0, moved = 0, partial = 0;
  for (size_t p = 0; p < records.pages.size(); ++p) {
    AtlasPage& page = gbuffer.pages[p];
    for (uint32_t k = 0; k < records.pages[p].live_texels; ++k, ++index) {
      if (index >= records.texels.size()) throw FormatError("scene.bin: pages list more live texels than there are");
      const formats::TexelRecord& r = records.texels[index];
      if (r.triangle >= scene.triangle_count() || r.x >= uint32_t(page.width) || r.y >= uint32_t(page.height))
        throw FormatError("scene.bin: texel " + std::to_string(index) + " does not fit the scene or its page");
      LiveTexel& texel = gbuffer.texels[index];
      texel.page = uint32_t(p);
      texel.x = r.x;
      texel.y = r.y;
      texel.instance = scene.triangle_instance[r.triangle];
      texel.triangle = r.triangle;
      texel.world_texel_size = records.triangle_texel_size[r.triangle];
      if (moved < records.moved.size() && records.moved[moved].texel == index) ++moved;
      float coverage = 1.0f;
      if (partial < records.partial_coverage.size() && records.partial_coverage[partial].texel == index)
        coverage = records.partial_coverage[partial++].coverage;
      page.coverage[size_t(r.y) * size_t(page.width) + r.x] = coverage;
    }
  }
  if (index != records.texels.size() || moved != records.moved.size() || partial != records.partial_coverage.size())
    throw FormatError(
        "scene.bin: live texel counts, the partial coverage or the moved-texel table do not match the texels");
  for_each_chunk(gbuffer.texels.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const formats::TexelRecord& r = records.texels[i];
      const TexelSurface surface = texel_surface(scene, r.triangle, r.b1, r.b2);
      LiveTexel& texel = gbuffer.texels[i];
      texel.position = surface.position;
      texel.geometric_normal = surface.geometric_normal;
      texel.shading_normal = surface.shading_normal;
      texel.albedo = surface.albedo;
    }
  }, 4096);
  for (const formats::MovedTexelRecord& m : records.moved) {
    const formats::Float3& position = m.position;
    gbuffer.texels[m.texel].position = {position[0], position[1], position[2]};
  }
  gbuffer.skipped_texels = area - records.texels.size();
  return gbuffer;
}

}  // namespace exitance
