// What each refreshed light probe shows (RefreshSession::published_probes; docs/runtime.md
// "Probes"): the lightmap's publishing rule (publishing_rule.h publish_after_restart) on the probe's
// L0 terms, which its sums keep squared, between the value it showed before the last edit and its
// refreshed estimate of the edited scene; and that kept value scaled by an edit that only scales
// lights, by the refreshed estimate's split into light layers.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/vec_math.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

// What a probe showed before the last edit, as probes.bin stores it (mean SH, deringed), with the
// samples and L0 variance of the mean (summed over rgb) behind it; variance < 0: unknown (the
// bundle's probes.bin), then the refreshed estimate takes over once it has `switch_samples`.
struct KeptProbe {
  std::array<float, 27> sh{};
  uint32_t samples = 0;
  double variance = -1;
};

// Whether probe `k` shows its refreshed estimate (`refreshed`, read back with its squared L0 sums)
// rather than `kept`.
bool probe_shows_refreshed(const KeptProbe& kept, const ProbeEstimate& refreshed, size_t k, uint32_t switch_samples);

// The dering window's weight per SH band, as store_probe_radiance applies it (none, 0: 1).
std::array<float, 3> probe_band_weights(float dering_window);

// During a change estimate of light edits (as the lightmap's, path.h punctual_change_rays; the probes'
// sums then hold the change from `base`, what they showed at its first edit): probe k's choice by
// publishing_rule.h's publish_after_change on the L0 terms of its change (read back with squared L0
// sums): kPublishPrevious, kPublishBase or kPublishRefreshed.
uint32_t probe_change_choice(const KeptProbe& base, const ProbeEstimate& change, size_t k);

// base + probe k's mean change, each coefficient's change times `band_weight` of its band (the dering
// window; the base, as shown, is deringed already); a sum that is not finite keeps the base's value.
// Its samples the base's, its variance the base's plus the change's (unknown stays unknown).
// publish_probes.comp makes the same float operations.
KeptProbe probe_base_plus_change(const KeptProbe& base, const ProbeEstimate& change, size_t k, const std::array<float, 3>& band_weight);

// An edit that scaled light layer `factor.w`'s emission by factor.xyz: each kept value plus
// (factor - 1) times that layer's refreshed mean (`layer`: ProbeRefresh::read_layer, deringed with
// `dering_window` as the kept values are), its variance in proportion to its L0's squared change.
// Probes with no refreshed sample keep their value (their refreshed estimate replaces it later).
void scale_kept_probes(std::vector<KeptProbe>& kept, const ProbeEstimate& layer, Vec4 factor, float dering_window);

// The order to refresh probes in after an edit whose change is local: nearest first, by the distance
// to the nearest of `points` (lights before and after a move) and `boxes` (moved instances' bounds
// before and after); empty (the probes' own order) when there is neither. `near` (may be null): how
// many of them lie near the change, as texels_near_change counts texels near: within twice a box's
// half-diagonal of it, and at least `near_floor` (a tenth of the scene's extent) of it or a point.
std::vector<uint32_t> probes_nearest_first(const std::vector<Vec3>& positions, const std::vector<Vec3>& points,
                                           const std::vector<WorldBox>& boxes, float near_floor = 0, size_t* near = nullptr);

}  // namespace exitance
