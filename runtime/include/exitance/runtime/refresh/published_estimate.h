// What a texel publishes while the runtime refreshes (docs/runtime.md "Never worse than before the
// edit"). The value a texel showed before an edit is an estimate of the edited scene too, exact
// where the edit changed nothing there and biased by the change elsewhere; the refreshed estimate is
// unbiased but noisy. A texel keeps its previous value unless the refreshed estimate is the more
// precise one or differs from it significantly: |D|^2 > kSignificance^2 V_D, with D the difference
// of the two, V_D its variance (variances of the mean, summed over the colour channels). Choosing by
// the lower estimated error instead (V_kept + max(0, |D|^2 - V_D) against V_refreshed) switched
// about a sixth of the unchanged texels to the noisy estimate (H200, city block moved: relMSE 0.0066
// after 60 frames against 0.0036 after 20; bench/results/refresh-change.md). The refreshed estimate
// needs 2 samples (a change) or kRestartMinimumSamples (a restart) first.
// Estimates are LightmapEstimate sums; a composite's sums are synthesized to give its mean and
// variance of the mean exactly (so the bundle's error layer and relMSE estimates read it as usual).
#pragma once
#include "exitance/common/publishing_rule.h"
#include "exitance/runtime/core/estimates.h"

namespace exitance {

// base + change per texel (the change estimate of RefreshSession's light edits, path.h
// punctual_change_rays, is an unbiased estimate of E/pi(edited) - E/pi(base)): means and every
// layer add, variances of the mean add (the two are independent), the sample count is the sum.
// Texels where either has no samples: base alone (change has none) or nothing. Same shapes required
// (std::invalid_argument).
LightmapEstimate add_change(const LightmapEstimate& base, const LightmapEstimate& change);

// Whether `estimate` can be the base of a change estimate: some texel has a variance (2 samples or
// more) and none has a single sample (texels with none, e.g. sealed texels a bake skipped, keep
// showing nothing).
bool can_be_change_base(const LightmapEstimate& estimate);

// After a light edit estimated as a change from `base`: per texel, `previous` (what it showed before
// the edit) while the change has fewer than 2 samples, then base + change where showing it has the
// lower estimated error (|d|^2 > kChangeShownAbove V_d summed over channels, publishing_rule.h),
// else base.
LightmapEstimate publish_change(const LightmapEstimate& previous, const LightmapEstimate& base, const LightmapEstimate& change);

// After any other edit (or none, from a bundle's baked lighting): `refreshed` is accumulated from
// nothing, independent of `previous`: per texel the rule above with V_D = V_previous + V_refreshed,
// once it has kRestartMinimumSamples, or as many as the kept value had if that is fewer (at least
// 2): a variance from 2 samples is below a tenth of the true one a quarter of the time, and the
// rule would then trade a converged value for a 2-sample one, while an object moved every frame
// and refreshed a few samples per frame must still show its moves;
// texels that had nothing before show the refreshed estimate.
LightmapEstimate publish_restart(const LightmapEstimate& previous, const LightmapEstimate& refreshed);

}  // namespace exitance
