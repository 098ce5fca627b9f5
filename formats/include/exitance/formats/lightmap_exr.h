// lightmap-<page>.exr: OpenEXR, float32, scanline, ZIP compressed. Channel layers are named
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

// Throws std::runtime_error on I/O failure.
void write_lightmap_exr(const std::string& path, const LightmapImage& image);
LightmapImage read_lightmap_exr(const std::string& path);

}  // namespace exitance::formats
