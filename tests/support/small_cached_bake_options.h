// A quick CPU bake of a test scene with a bundle cache folder (empty: no cache): density 8, 4 spp,
// 16 rays per probe. The cache tests bake small scenes many times with it.
#pragma once
#include <filesystem>

#include "exitance/bake/bake_options.h"

namespace exitance {

inline BakeOptions small_cached_bake_options(const std::filesystem::path& input, const std::filesystem::path& out,
                                             const std::filesystem::path& cache) {
  BakeOptions options;
  options.input = input.string();
  options.output = out.string();
  options.cache_directory = cache.string();
  options.backend.name = "cpu";
  options.atlas.texel_density = 8;
  options.lighting.spp = 4;
  options.probe_spp = 16;
  return options;
}

}  // namespace exitance
