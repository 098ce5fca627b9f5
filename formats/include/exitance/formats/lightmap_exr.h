// lightmap-<page>.exr: OpenEXR, float32, scanline, ZIP compressed (OpenEXR's ZIP chunks, deflated
// by libdeflate at level 4: the compression and its encoder chosen by measurement,
// bench/results/host-stages.md; any OpenEXR reader reads them). Channel layers are named
// "<layer>.R/G/B" except the main one, which is plain R, G, B plus A (texel coverage) and `valid`
// (1 = the texel was traced; 0 = gutter, or a sealed texel that no light reaches, skipped by bake and
// filled by dilation from its traced neighbours: docs/bundle.md), and the single-channel `error.Y`
// (the texel's estimated relative standard error).
#pragma once
#include <map>
#include <string>
#include <vector>

namespace exitance::formats {

struct LightmapImage {
  int width = 0;
  int height = 0;
  // Channel name -> width*height floats, row 0 = top. E.g. "R", "G", "B", "A", "direct.R".
  std::map<std::string, std::vector<float>> channels;
};

// Throw std::runtime_error naming the file on I/O failure (a page that fails to write is removed).
// `threads`: worker threads that compress (write: threads of the writer's own) or decompress (read:
// OpenEXR's pool) the file's blocks; -1 = lightmap_exr_threads(), 0 = all on the calling thread.
// The file's bytes and the pixels read do not depend on it (tests/formats).
void write_lightmap_exr(const std::string& path, const LightmapImage& image, int threads = -1);
LightmapImage read_lightmap_exr(const std::string& path, int threads = -1);

// One per hardware thread. The first call raises OpenEXR's process-wide pool
// (Imf::setGlobalThreadCount) to that many threads if it has fewer; a larger pool set by the
// program is kept.
int lightmap_exr_threads();

}  // namespace exitance::formats
