// relMSE of bundles' lightmaps against a reference made of two bundles of the same scene and atlas
// (different seeds), reading only the bundle format (formats/, OpenEXR): runs where the runtime's
// relocatable folder runs, e.g. beside exitance-relight on a GPU machine.
//   bench_bundle_rel_mse REF_A.bake REF_B.bake TEST.bake [TEST.bake ...]
// Texels: fully covered (A = 1) and traced (valid > 0) in REF_A, on every lightmap-*.exr page.
// Reference r = (a + b) / 2. Its own noise, mean (a - b)^2 / 4 / (r^2 + 1e-3) (E[(a - b)^2] = 2 Var
// and r averages two runs), is printed and subtracted from each TEST's mean (x - r)^2 / (r^2 + 1e-3):
// what remains is the TEST's error against the converged answer, bias included.
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "rel_mse_weight.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_bundle_rel_mse REF_A.bake REF_B.bake TEST.bake [TEST.bake ...]\n");
    return 2;
  }
  try {
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
    for (const std::string& page : pages) {
      const exitance::formats::LightmapImage a = exitance::formats::read_lightmap_exr((fs::path(argv[1]) / page).string());
      const exitance::formats::LightmapImage b = exitance::formats::read_lightmap_exr((fs::path(argv[2]) / page).string());
      std::vector<exitance::formats::LightmapImage> tests;
      for (int t = 3; t < argc; ++t) tests.push_back(exitance::formats::read_lightmap_exr((fs::path(argv[t]) / page).string()));
      const size_t n = a.channels.at("R").size();
      for (size_t i = 0; i < n; ++i) {
        if (!(a.channels.at("A")[i] >= 1.0f) || !(a.channels.at("valid")[i] > 0)) continue;
        ++texels;
        for (const char* c : channels) {
          const double va = a.channels.at(c)[i], vb = b.channels.at(c).at(i), r = 0.5 * (va + vb);
          const double w = rel_mse_weight(r);
          noise += 0.25 * (va - vb) * (va - vb) * w;
          for (size_t t = 0; t < tests.size(); ++t) {
            const double x = tests[t].channels.at(c).at(i);
            sums[t] += (x - r) * (x - r) * w;
          }
        }
      }
    }
    const double count = 3.0 * double(texels);
    std::printf("texels %zu, reference noise relMSE %.6g\n", texels, noise / count);
    for (size_t t = 0; t < sums.size(); ++t)
      std::printf("%s relMSE %.6g (raw %.6g)\n", argv[t + 3], sums[t] / count - noise / count, sums[t] / count);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_bundle_rel_mse: %s\n", e.what());
    return 2;
  }
  return 0;
}
