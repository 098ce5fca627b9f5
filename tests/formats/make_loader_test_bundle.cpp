// Writes the test bundles the sample and install tests load: DIR/full (lightmaps, probes, SVO)
// and DIR/lightmaps_only.
#include <cstdio>
#include <exception>

#include "test_bundle.h"
#include "test_manifest.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  try {
    namespace t = exitance::test;
    const std::string dir = argv[1];
    const auto grid = t::make_linear_probe_grid();
    const auto svo = t::make_test_octree();
    t::write_bundle(dir + "/full", t::make_manifest(grid, svo).dump(2), grid, svo);
    t::write_bundle(dir + "/lightmaps_only", t::make_manifest(std::nullopt, std::nullopt).dump(2), std::nullopt, std::nullopt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_loader_test_bundle: %s\n", e.what());
    return 1;
  }
  return 0;
}
