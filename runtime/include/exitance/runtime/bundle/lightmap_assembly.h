// Turns per-texel estimates into atlas page images: E/pi in R,G,B, coverage in A, `valid` (1 where
// the texel was traced), direct/indirect layers, the estimated relative standard error in error.Y
// (LightmapEstimate::relative_standard_error with the estimate's error_floor), optional bounce<k>
// layers, the L1 SH layers sh1.x/y/z.R/G/B when the estimate has them, and gutter texels dilated
// from their neighbours.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct AssemblyOptions {
  bool bounce_layers = false;  // write bounce<k>.R/G/B debug layers
  int dilation_texels = 4;     // how far colour is pushed into the gutter
};

// `untraced`: per live texel, 1 for a texel the lighting stage skipped (sealed: no light reaches
// it), or empty for none. Untraced texels keep their coverage in A, get valid = 0 and take every
// colour channel from their traced neighbours (dilated within the charts, as far as it takes); one
// with no traced texel connected to it stays 0.
std::vector<formats::LightmapImage> assemble_lightmap_pages(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate,
                                                            const AssemblyOptions& options,
                                                            const std::vector<uint8_t>& untraced = {});

// The same, one page at a time into an image whose arrays are reused from page to page (bake's
// write assembles, stitches and writes each page before the next: a page's channels are ~180 MB
// at 2048 x 1848, all of a 27-page bake's 4.9 GB). The references must outlive the assembler.
class LightmapPageAssembler {
 public:
  LightmapPageAssembler(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate, const AssemblyOptions& options,
                        const std::vector<uint8_t>& untraced = {});
  size_t page_count() const { return gbuffer_.pages.size(); }
  // Page `p` into `image`: every channel of every cell written, as assemble_lightmap_pages makes it.
  void assemble(size_t p, formats::LightmapImage& image) const;

 private:
  const TexelGBuffer& gbuffer_;
  const LightmapEstimate& estimate_;
  AssemblyOptions options_;
  std::vector<uint8_t> untraced_;
  std::vector<std::string> layers_;
  double error_floor_ = 0;
  std::vector<uint32_t> page_start_, by_page_;  // live texels per page, in texel order
};

// A page file of a bundle (lightmap or light layers) read back as atlas page `page` of `gbuffer`:
// throws std::runtime_error naming `path` when it cannot be read or its size is not the page's.
formats::LightmapImage read_atlas_page(const std::string& path, const TexelGBuffer& gbuffer, size_t page);

// Fills texels whose coverage is 0 with the mean of already-filled 8-neighbours, `passes` rings deep.
void dilate_into_gutter(int width, int height, const std::vector<float>& coverage, std::vector<float*> channels,
                        int passes);

// The same ring by ring fill in general: texels with `filled` = 0 and `fillable` = 1 take the mean of
// their filled 8-neighbours, `passes` rings deep (a negative count: until nothing changes).
void dilate_into(int width, int height, std::vector<uint8_t> filled, const std::vector<uint8_t>& fillable,
                 std::vector<float*> channels, int passes);

}  // namespace exitance
