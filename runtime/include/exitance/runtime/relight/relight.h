// Re-lighting a baked bundle from its scene.bin on the GPU, with no offline stage: what
// exitance-relight runs and what an engine calls through libexitance_runtime. A full relight never
// reads the input's lightmaps, probe coefficients or voxel exitance: it recomputes them all.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace exitance {

struct RelightOptions {
  std::string bundle;              // the input bundle folder (manifest.json + scene.bin + svo.bin ...)
  std::string output;              // empty: the input bundle, replaced atomically
  std::optional<uint32_t> spp;     // default: the bake's (manifest settings.spp)
  double time_budget_seconds = 0;  // > 0: stop the lightmap pass when spent (no sample cap unless spp is given)
  std::optional<uint64_t> seed;    // default: the bake's
  int device_index = -1;           // Vulkan device; -1 = prefer a discrete GPU
  bool validation = false;         // Vulkan validation layers; any message fails the relight
  bool stage_statistics = false;   // GPU time, rays and lane efficiency per wavefront stage (slower; benchmarks)
  uint32_t traversal_rays = 0;     // > 0: also time this many incoherent closest-hit rays alone (benchmarks)
  // Stage reporting: (stage, fraction done, rays so far).
  std::function<void(const std::string&, double, uint64_t)> progress;
};

// Bad input: a missing or malformed manifest, scene.bin or svo.bin, an impossible option. The
// message names the file, the element and the problem, on one line (exit status 2).
class RelightInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Runs the relight and writes the bundle atomically (nothing is written on failure). Returns the
// run report (what the manifest's "relight" and "stats" entries say). Throws RelightInputError
// for bad input and std::runtime_error for other failures (no Vulkan device, device loss).
nlohmann::json relight_bundle(const RelightOptions& options);

}  // namespace exitance
