// relMSE of lightmap pages against a reference page, over the texels a bundle traced:
//   bench_compare_lightmap_pages BUNDLE_PAGE.exr REFERENCE TEST [TEST ...]
//   bench_compare_lightmap_pages BUNDLE_PAGE.exr REFERENCE --pair A B
// BUNDLE_PAGE.exr (a bundle's lightmap-K.exr) picks the texels: fully covered (A = 1) and traced (valid > 0).
// Only fully covered texels: Cycles bakes a texel only where its centre lies on a triangle (and leaves
// the others black with margin 0), while a bundle also lights texels a chart covers in part.
// REFERENCE and every TEST are images OpenImageIO reads (a bundle page, or the .pfm pages
// bench/cycles/cycles_bake.py writes) whose first three channels, or R, G, B where named, are E/pi.
// relMSE = mean over those texels and channels of (x - r)^2 / (r^2 + 1e-3), as bench_time_to_error
// computes it. One line per TEST: file, texels, relMSE, mean(x) / mean(r).
// --pair: A and B are two runs of one renderer with different seeds; E[(a - b)^2] = 2 Var, so
// mean (a - b)^2 / (2 (r^2 + 1e-3)) is the relMSE of one run from its noise alone, whatever its bias and
// however noisy REFERENCE is (it only weights the texels). Prints: texels, noise relMSE.
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "../rel_mse_weight.h"

namespace {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row 0 = top
};

RgbImage read_rgb(const std::string& path) {
  auto input = OIIO::ImageInput::open(path);
  if (!input) throw std::runtime_error(path + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = input->spec();
  int first = 0;  // R, G, B by name where the file names them (a bundle page lists A first)
  for (int c = 0; c < spec.nchannels; ++c)
    if (spec.channelnames[c] == "R") first = c;
  if (spec.nchannels < first + 3) throw std::runtime_error(path + ": fewer than 3 channels");
  RgbImage image{spec.width, spec.height, std::vector<float>(size_t(spec.width) * spec.height * 3)};
  if (!input->read_image(0, 0, first, first + 3, OIIO::TypeDesc::FLOAT, image.rgb.data()))
    throw std::runtime_error(path + ": " + input->geterror());
  return image;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s BUNDLE_PAGE.exr REFERENCE TEST [TEST ...]\n", argv[0]);
    return 2;
  }
  try {
    const auto mask = exitance::formats::read_lightmap_exr(argv[1]);
    const auto& coverage = mask.channels.at("A");
    const auto valid = mask.channels.find("valid");
    const RgbImage reference = read_rgb(argv[2]);
    if (reference.width != mask.width || reference.height != mask.height)
      throw std::runtime_error(std::string(argv[2]) + ": size differs from " + argv[1]);
    const bool pair = std::string(argv[3]) == "--pair";
    if (pair && argc != 6) throw std::runtime_error("--pair takes two images");
    for (int t = pair ? 4 : 3; t < argc; t += pair ? 2 : 1) {
      const RgbImage test = read_rgb(argv[t]);
      if (test.width != mask.width || test.height != mask.height)
        throw std::runtime_error(std::string(argv[t]) + ": size differs from " + argv[1]);
      const RgbImage other = pair ? read_rgb(argv[t + 1]) : RgbImage{};
      if (pair && (other.width != mask.width || other.height != mask.height))
        throw std::runtime_error(std::string(argv[t + 1]) + ": size differs from " + argv[1]);
      double rel_mse = 0, sum_x = 0, sum_r = 0;
      size_t texels = 0;
      for (size_t i = 0; i < coverage.size(); ++i) {
        if (!(coverage[i] >= 1.0f) || (valid != mask.channels.end() && !(valid->second[i] > 0))) continue;
        ++texels;
        for (int c = 0; c < 3; ++c) {
          const double x = test.rgb[3 * i + c], r = reference.rgb[3 * i + c];
          const double d = pair ? x - other.rgb[3 * i + c] : x - r;
          rel_mse += d * d * rel_mse_weight(r) / (pair ? 2.0 : 1.0);
          sum_x += x, sum_r += r;
        }
      }
      if (pair) {
        std::printf("%s %s texels %zu noise_rel_mse %.6g\n", argv[t], argv[t + 1], texels,
                    texels ? rel_mse / (3.0 * double(texels)) : 0.0);
        continue;
      }
      std::printf("%s texels %zu rel_mse %.6g mean_ratio %.5f\n", argv[t], texels,
                  texels ? rel_mse / (3.0 * double(texels)) : 0.0, sum_r > 0 ? sum_x / sum_r : 0.0);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_compare_lightmap_pages: %s\n", e.what());
    return 2;
  }
  return 0;
}
