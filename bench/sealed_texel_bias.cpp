// What skipping sealed texels changes (bench/results/dead-work.md): reads two bundles of one scene,
// baked with the same options with and without --no-skip, finds the texels the skipping bake did
// not trace (A > 0, valid = 0) and prints the E/pi the --no-skip bake traced there (the skip's bias:
// ~0 when the test is right), beside the mean over the traced texels for scale. Also counts
// non-finite values in every channel of the skipping bundle.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "exitance/formats/lightmap_exr.h"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using exitance::formats::LightmapImage;
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SKIP.bake NO_SKIP.bake\n", argv[0]);
    return 2;
  }
  size_t sealed = 0, traced = 0, nonfinite = 0, pages = 0;
  double sealed_sum = 0, sealed_max = 0, traced_sum = 0, filled_sum = 0;
  for (int p = 0;; ++p) {
    const std::string name = "lightmap-" + std::to_string(p) + ".exr";
    if (!fs::exists(fs::path(argv[1]) / name)) break;
    const LightmapImage skip = exitance::formats::read_lightmap_exr((fs::path(argv[1]) / name).string());
    const LightmapImage full = exitance::formats::read_lightmap_exr((fs::path(argv[2]) / name).string());
    ++pages;
    for (const auto& [channel, data] : skip.channels)
      for (float v : data) nonfinite += !std::isfinite(v);
    const auto& a = skip.channels.at("A");
    const auto& valid = skip.channels.at("valid");
    for (size_t i = 0; i < a.size(); ++i) {
      if (!(a[i] > 0)) continue;
      // E/pi as the mean of R, G, B; the max over the channels.
      const double e = (full.channels.at("R")[i] + full.channels.at("G")[i] + full.channels.at("B")[i]) / 3.0;
      const double m = std::fmax(full.channels.at("R")[i], std::fmax(full.channels.at("G")[i], full.channels.at("B")[i]));
      if (valid[i] > 0) {
        traced_sum += e, ++traced;
        continue;
      }
      ++sealed;
      sealed_sum += e;
      sealed_max = std::fmax(sealed_max, m);
      filled_sum += (skip.channels.at("R")[i] + skip.channels.at("G")[i] + skip.channels.at("B")[i]) / 3.0;
    }
  }
  std::printf("pages %zu, traced texels %zu (mean E/pi %.6g), sealed texels %zu\n", pages, traced,
              traced ? traced_sum / double(traced) : 0.0, sealed);
  std::printf("sealed texels traced by --no-skip: mean E/pi %.6g, max channel %.6g\n",
              sealed ? sealed_sum / double(sealed) : 0.0, sealed_max);
  std::printf("sealed texels in the skipping bundle (dilated): mean E/pi %.6g; non-finite values in it: %zu\n",
              sealed ? filled_sum / double(sealed) : 0.0, nonfinite);
  return 0;
}
