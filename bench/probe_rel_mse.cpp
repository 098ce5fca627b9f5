// relMSE of bundles' light probes against a reference made of two bundles of the same scene and
// probe grid (different seeds), reading only probes.bin (formats/): runs beside exitance-relight on a
// GPU machine, as bench_bundle_rel_mse does for the lightmap.
//   bench_probe_rel_mse [--changed BEFORE_A.bake BEFORE_B.bake] REF_A.bake REF_B.bake TEST.bake [TEST.bake ...]
// What a probe is for is the irradiance it gives a surface: per usable probe (probes.bin state valid
// or moved in REF_A) and per axis normal (+-x, +-y, +-z), E/pi from its L2 SH (the clamped-cosine
// convolution the loader applies), per channel. Reference r = (a + b) / 2; its own noise, mean
// (a - b)^2 / 4 / (r^2 + 1e-3), is printed and subtracted from each TEST's mean (x - r)^2 / (r^2 +
// 1e-3), as bench_bundle_rel_mse does.
// --changed: two references of the scene before an edit; also the same figures over the probes the
// edit changed, those whose 18 values moved between the references by more than 3 sigma of the
// four runs' noise (sum of (r_after - r_before)^2 > 9 x sum of ((a - b)^2 + (a0 - b0)^2) / 4): an
// edit in one room changes a few probes of a building, whose error the whole grid's noise hides.
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/formats/probes_file.h"
#include "exitance/runtime/spherical_harmonics.h"
#include "rel_mse_weight.h"

namespace fs = std::filesystem;
using namespace exitance;

namespace {

// Per usable probe of `usable`, six normals, three channels: E/pi.
std::vector<double> irradiance_values(const std::string& bundle, const formats::ProbeGrid* usable) {
  const formats::ProbeGrid grid = formats::read_probes_file((fs::path(bundle) / "probes.bin").string());
  if (usable && grid.probes.size() != usable->probes.size())
    throw std::runtime_error(bundle + "/probes.bin: " + std::to_string(grid.probes.size()) + " probes, the reference has " +
                             std::to_string(usable->probes.size()));
  const formats::ProbeGrid& which = usable ? *usable : grid;
  const Vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<double> values;
  for (size_t p = 0; p < grid.probes.size(); ++p) {
    if (!formats::probe_is_usable(which.probes[p])) continue;
    ShRgb sh;
    for (size_t i = 0; i < sh.size(); ++i) sh[i] = Vec3{grid.probes[p].sh[i * 3], grid.probes[p].sh[i * 3 + 1], grid.probes[p].sh[i * 3 + 2]};
    for (const Vec3& n : normals) {
      const Vec3 e = sh_irradiance_over_pi(sh, n);
      values.insert(values.end(), {double(e.x), double(e.y), double(e.z)});
    }
  }
  return values;
}

}  // namespace

// Mean over the values of the probes in `selected` (all when empty) of the reference's noise and of
// each TEST's weighted squared error.
struct Figures {
  size_t probes = 0;
  double noise = 0;
  std::vector<double> error;
};
Figures figures(const std::vector<double>& a, const std::vector<double>& b, const std::vector<std::vector<double>>& tests,
                const std::vector<bool>& selected) {
  Figures f;
  f.error.assign(tests.size(), 0.0);
  size_t values = 0;
  for (size_t p = 0; p < a.size() / 18; ++p) {
    if (!selected.empty() && !selected[p]) continue;
    ++f.probes;
    for (size_t i = p * 18; i < p * 18 + 18; ++i, ++values) {
      const double r = 0.5 * (a[i] + b[i]);
      f.noise += 0.25 * (a[i] - b[i]) * (a[i] - b[i]) * rel_mse_weight(r);
      for (size_t t = 0; t < tests.size(); ++t) f.error[t] += (tests[t][i] - r) * (tests[t][i] - r) * rel_mse_weight(r);
    }
  }
  if (values > 0) {
    f.noise /= double(values);
    for (double& e : f.error) e /= double(values);
  }
  return f;
}

void print(const Figures& f, const char* what, char** names) {
  std::printf("%s: %zu probes, reference noise %.6g\n", what, f.probes, f.noise);
  for (size_t t = 0; t < f.error.size(); ++t) std::printf("  %s: relMSE %.6g (raw %.6g)\n", names[t], f.error[t] - f.noise, f.error[t]);
}

int main(int argc, char** argv) {
  const char* before_a = nullptr;
  const char* before_b = nullptr;
  if (argc >= 4 && std::string(argv[1]) == "--changed") before_a = argv[2], before_b = argv[3], argv += 3, argc -= 3;
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_probe_rel_mse [--changed BEFORE_A.bake BEFORE_B.bake] REF_A.bake REF_B.bake TEST.bake [TEST.bake ...]\n");
    return 2;
  }
  try {
    const formats::ProbeGrid reference_grid = formats::read_probes_file((fs::path(argv[1]) / "probes.bin").string());
    const std::vector<double> a = irradiance_values(argv[1], &reference_grid);
    const std::vector<double> b = irradiance_values(argv[2], &reference_grid);
    if (a.empty()) throw std::runtime_error(std::string(argv[1]) + "/probes.bin: no usable probe");
    std::vector<std::vector<double>> tests;
    for (int t = 3; t < argc; ++t) tests.push_back(irradiance_values(argv[t], &reference_grid));
    print(figures(a, b, tests, {}), "all usable probes", argv + 3);
    if (before_a) {
      const std::vector<double> a0 = irradiance_values(before_a, &reference_grid);
      const std::vector<double> b0 = irradiance_values(before_b, &reference_grid);
      std::vector<bool> changed(a.size() / 18, false);
      for (size_t p = 0; p < changed.size(); ++p) {
        double moved = 0, noise = 0;
        for (size_t i = p * 18; i < p * 18 + 18; ++i) {
          const double d = 0.5 * (a[i] + b[i]) - 0.5 * (a0[i] + b0[i]);
          moved += d * d;
          noise += 0.25 * ((a[i] - b[i]) * (a[i] - b[i]) + (a0[i] - b0[i]) * (a0[i] - b0[i]));
        }
        changed[p] = moved > 9.0 * noise;
      }
      print(figures(a, b, tests, changed), "probes the edit changed", argv + 3);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_probe_rel_mse: %s\n", e.what());
    return 2;
  }
  return 0;
}
