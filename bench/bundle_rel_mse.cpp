// relMSE of bundles' lightmaps against a reference made of two bundles of the same scene and atlas
// (different seeds), reading only the bundle format (formats/, OpenEXR): runs where the runtime's
// relocatable folder runs, e.g. beside exitance-relight on a GPU machine.
//   bench_bundle_rel_mse [--by-reference K] REF_A.bake REF_B.bake TEST.bake [TEST.bake ...]
// Texels: fully covered (A = 1) and traced (valid > 0) in REF_A, on every lightmap-*.exr page.
// Reference r = (a + b) / 2. Its own noise, mean (a - b)^2 / 4 / (r^2 + 1e-3) (E[(a - b)^2] = 2 Var
// and r averages two runs), is printed and subtracted from each TEST's mean (x - r)^2 / (r^2 + 1e-3):
// what remains is the TEST's error against the converged answer, bias included.
// --by-reference K: also, per TEST, where its error is: the texels in K bins of equal count by the
// reference's mean over the channels, each bin's mean reference and share of the TEST's raw sum.
// --worst N: also, per TEST, its N texels of largest error (page, column, row, reference and TEST
// channel means, share of the raw sum) and how few texels hold half its raw sum: a
// few texels far off (a lit value where the reference is black) can dominate relMSE.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "rel_mse_weight.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  int bins = 0, worst = 0;
  while (argc >= 3 && (std::string(argv[1]) == "--by-reference" || std::string(argv[1]) == "--worst")) {
    const bool by_reference = std::string(argv[1]) == "--by-reference";
    const int value = std::atoi(argv[2]);
    if (value < 1 || value > (by_reference ? 100 : 10000)) {
      std::fprintf(stderr, "bench_bundle_rel_mse: %s: must be 1 to %d, got '%s'\n", argv[1], by_reference ? 100 : 10000, argv[2]);
      return 2;
    }
    (by_reference ? bins : worst) = value;
    argv += 2, argc -= 2;
  }
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_bundle_rel_mse [--by-reference K] [--worst N] REF_A.bake REF_B.bake TEST.bake [TEST.bake ...]\n");
    return 2;
  }
  try {
    // Per compared texel: the reference's channel mean, and per TEST its weighted squared error.
    std::vector<double> reference_of_texel;
    struct Where {
      uint32_t page, x, y;
    };
    std::vector<Where> where_of_texel;
    std::vector<std::vector<double>> test_of_texel(size_t(argc - 3));  // --worst: each TEST's channel mean
    std::vector<std::vector<double>> error_of_texel(size_t(argc - 3));
    std::vector<std::string> pages;
    for (const auto& entry : fs::directory_iterator(argv[1])) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("lightmap-", 0) == 0 && entry.path().extension() == ".exr") pages.push_back(name);
    }
    if (pages.empty()) throw std::runtime_error(std::string(argv[1]) + ": no lightmap-*.exr pages");
    const char* channels[3] = {"R", "G", "B"};
    double noise = 0;
    std::vector<double> sums(size_t(argc - 3), 0.0);
    size_t texels = 0;
    for (size_t page_index = 0; page_index < pages.size(); ++page_index) {
      const std::string& page = pages[page_index];
      const exitance::formats::LightmapImage a = exitance::formats::read_lightmap_exr((fs::path(argv[1]) / page).string());
      const exitance::formats::LightmapImage b = exitance::formats::read_lightmap_exr((fs::path(argv[2]) / page).string());
      std::vector<exitance::formats::LightmapImage> tests;
      for (int t = 3; t < argc; ++t) tests.push_back(exitance::formats::read_lightmap_exr((fs::path(argv[t]) / page).string()));
      const size_t n = a.channels.at("R").size();
      for (size_t i = 0; i < n; ++i) {
        if (!(a.channels.at("A")[i] >= 1.0f) || !(a.channels.at("valid")[i] > 0)) continue;
        ++texels;
        double reference_mean = 0;
        std::vector<double> texel_error(tests.size(), 0.0), texel_value(tests.size(), 0.0);
        for (const char* c : channels) {
          const double va = a.channels.at(c)[i], vb = b.channels.at(c).at(i), r = 0.5 * (va + vb);
          const double w = rel_mse_weight(r);
          noise += 0.25 * (va - vb) * (va - vb) * w;
          reference_mean += r / 3;
          for (size_t t = 0; t < tests.size(); ++t) {
            const double x = tests[t].channels.at(c).at(i);
            sums[t] += (x - r) * (x - r) * w;
            texel_error[t] += (x - r) * (x - r) * w;
            texel_value[t] += x / 3;
          }
        }
        if (bins > 0 || worst > 0) {
          reference_of_texel.push_back(reference_mean);
          for (size_t t = 0; t < tests.size(); ++t) error_of_texel[t].push_back(texel_error[t]);
        }
        if (worst > 0) {
          where_of_texel.push_back({uint32_t(page_index), uint32_t(i % size_t(a.width)), uint32_t(i / size_t(a.width))});
          for (size_t t = 0; t < tests.size(); ++t) test_of_texel[t].push_back(texel_value[t]);
        }
      }
    }
    const double count = 3.0 * double(texels);
    std::printf("texels %zu, reference noise relMSE %.6g\n", texels, noise / count);
    for (size_t t = 0; t < sums.size(); ++t)
      std::printf("%s relMSE %.6g (raw %.6g)\n", argv[t + 3], sums[t] / count - noise / count, sums[t] / count);
    if (bins > 0 && texels > 0) {
      std::vector<size_t> order(texels);
      std::iota(order.begin(), order.end(), size_t(0));
      std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return reference_of_texel[x] < reference_of_texel[y]; });
      for (size_t t = 0; t < sums.size(); ++t) {
        std::printf("%s by reference (bin: texels, mean reference, share of the raw sum):", argv[t + 3]);
        for (int k = 0; k < bins; ++k) {
          const size_t first = texels * size_t(k) / size_t(bins), end = texels * size_t(k + 1) / size_t(bins);
          double reference = 0, error = 0;
          for (size_t j = first; j < end; ++j) reference += reference_of_texel[order[j]], error += error_of_texel[t][order[j]];
          std::printf(" [%zu %.4g %.3f]", end - first, end > first ? reference / double(end - first) : 0.0,
                      sums[t] > 0 ? error / sums[t] : 0.0);
        }
        std::printf("\n");
      }
    }
    for (size_t t = 0; worst > 0 && t < sums.size() && texels > 0; ++t) {
      std::vector<size_t> order(texels);
      std::iota(order.begin(), order.end(), size_t(0));
      std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return error_of_texel[t][x] > error_of_texel[t][y]; });
      size_t half = 0;
      for (double held = 0; half < texels && held < 0.5 * sums[t]; ++half) held += error_of_texel[t][order[half]];
      std::printf("%s: %zu texels hold half the raw sum; worst (page x y: reference, test, share):", argv[t + 3], half);
      for (size_t j = 0; j < std::min(texels, size_t(worst)); ++j) {
        const size_t k = order[j];
        std::printf(" [%s %u %u: %.4g %.4g %.4f]", pages[where_of_texel[k].page].c_str(), where_of_texel[k].x, where_of_texel[k].y,
                    reference_of_texel[k], test_of_texel[t][k], sums[t] > 0 ? error_of_texel[t][k] / sums[t] : 0.0);
      }
      std::printf("\n");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_bundle_rel_mse: %s\n", e.what());
    return 2;
  }
  return 0;
}
