// Picks the lighting backend for `bake --backend auto|vulkan|cpu`.
#pragma once
#include <memory>
#include <string>

#include "exitance/bake/bake_options.h"
#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/core/integrator.h"
#include "exitance/runtime/core/lighting_scene.h"

namespace exitance {

class EmbreeScene;

// auto: a GPU Vulkan device when one exists and supports the scene; otherwise the CPU reference,
// because on this project's 2-core CPU machines lavapipe measured 0.1-0.2x Embree's rays/s
// (bench/results/vulkan-lavapipe.md). Both backends read the same LightingScene; the CPU reference
// also shares the offline stage's Embree scene. Notices go to `diagnostics`. Throws
// std::runtime_error when `vulkan` is requested and impossible.
std::shared_ptr<const Integrator> choose_lighting_backend(std::shared_ptr<const LightingScene> scene,
                                                          std::shared_ptr<const EmbreeScene> embree,
                                                          const BackendRequest& request, Diagnostics& diagnostics);

// What `request` may choose among, for the bake cache's key: "cpu" for --backend cpu, else the
// Vulkan devices present (name, type, API version, usable).
std::string backend_candidates(const BackendRequest& request);

}  // namespace exitance
