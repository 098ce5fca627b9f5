// What `--guiding auto`'s measured choice kept and why (LightmapEstimate's guiding_* fields,
// core/guiding_choice.h) as JSON: the bake manifest's stats.guiding and exitance-relight's report
// write the same object (docs/bundle.md, docs/cli.md).
#pragma once
#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/guiding_choice.h"

namespace exitance {

// stats.guiding (--guiding auto): what the measured choice kept, and why (core/guiding_choice.h).
inline nlohmann::json guiding_auto_json(const LightmapEstimate& estimate, const std::string& backend) {
  // Vulkan, no candidate for this bake: the unguided bake, no pilot.
  if (estimate.guiding_auto_unmeasured) return {{"mode", "auto"}, {"candidate", "none"}, {"decided", false}};
  nlohmann::json out = {{"mode", "auto"},
                        {"candidate", estimate.guiding_auto_light_subpaths ? "light-paths" : "grid"},
                        {"pilot_samples_per_texel", estimate.guiding_auto_pilot},
                        // Light subpaths: the pilot's samples of texels that then connected, dropped (cpu_reference_integrator.cpp).
                        {"pilot_samples_dropped", estimate.pilot_samples_dropped},
                        {"guided_vertices", estimate.guided_vertices}};
  // Vulkan: the host's setup before the first pass (a time: differs run to run).
  if (estimate.guiding_auto_setup_seconds > 0) out["setup_seconds"] = estimate.guiding_auto_setup_seconds;
  const std::vector<RegionChoice>& regions = estimate.guiding_regions;
  if (regions.empty()) {
    out["decided"] = false;  // the bake ended within the pilot: every sample tossed the pilot's coin
    // ... or, light subpaths under --time, gave it up unmeasured in its first half (all unguided from there).
    if (estimate.guiding_auto_abandoned_at > 0) out["abandoned_at_samples_per_texel"] = estimate.guiding_auto_abandoned_at;
    return out;
  }
  size_t texels = 0, texels_guided = 0, regions_guided = 0, measured = 0, by_basis[3] = {0, 0, 0};
  std::vector<double> ratios;
  for (const RegionChoice& r : regions) {
    texels += r.texels;
    texels_guided += r.texels_guided;
    if (r.guided) ++regions_guided;
    ++by_basis[int(r.basis)];
    if (r.texels_measured == 0) continue;
    ++measured;
    ratios.push_back(r.efficiency_ratio);
  }
  std::sort(ratios.begin(), ratios.end());
  auto quantile = [&](double q) { return ratios.empty() ? 0.0 : ratios[std::min(ratios.size() - 1, size_t(q * double(ratios.size())))]; };
  const EfficiencyEvidence& scene = estimate.guiding_scene;
  out["decided"] = true;
  out["chose"] = regions_guided == 0 ? "off" : regions_guided == regions.size() ? "guided" : "per region";
  out["regions"] = regions.size();
  out["regions_measured"] = measured;
  out["regions_guided"] = regions_guided;
  // Where each region's strategy came from: its own significant evidence, the scene's, or neither (unguided).
  out["regions_by_basis"] = {{"region", by_basis[int(ChoiceBasis::Region)]},
                             {"scene", by_basis[int(ChoiceBasis::Scene)]},
                             {"default", by_basis[int(ChoiceBasis::Default)]}};
  out["texels_guided_fraction"] = texels > 0 ? double(texels_guided) / double(texels) : 0.0;
  // Relative variance x counted cost, unguided over guided: > 1 guiding pays. z: its difference in
  // standard errors (kChoiceZ decides).
  out["efficiency_ratio"] = {{"scene", scene.efficiency_ratio()},
                             {"scene_z", scene.z()},
                             {"regions_min", ratios.empty() ? 0.0 : ratios.front()},
                             {"regions_p50", quantile(0.5)},
                             {"regions_max", ratios.empty() ? 0.0 : ratios.back()}};
  out["cost_per_sample_rays"] = {{"unguided", scene.cost_per_sample(0)}, {"guided", scene.cost_per_sample(1)}};
  // Each backend's price of a guided vertex (core/guiding_choice.h).
  out["guided_vertex_cost_rays"] = backend == "vulkan" ? kGuidedVertexCostInRaysVulkan : kGuidedVertexCostInRays;
  out["guided_cost_factor"] = estimate.guiding_auto_cost_factor;  // on a guided sample's counted cost (Vulkan's connections)
  out["choice_z"] = kChoiceZ;
  return out;
}

}  // namespace exitance
