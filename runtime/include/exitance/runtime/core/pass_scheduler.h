// How a bake is cut into passes of samples, shared by every integrator and backend: the sample cap
// (spp), the time budget, a target error, and progress reports all live here once.
#pragma once
#include <chrono>
#include <cstdint>

#include "exitance/runtime/core/integrator_settings.h"

namespace exitance {

struct PassPolicy {
  // Most samples per item in one pass (a backend's preference: memory, submission length).
  uint32_t largest_pass = 0xFFFFFFFFu;
  // Passes of 1 sample, then 4 (from 4 samples), then 16 (from 64): early progress, and a time
  // budget or target error honoured at fine grain.
  bool ramp = false;
  // The ramp applies while fewer samples than this are done (a backend that needs the small passes
  // only early, e.g. Vulkan grid guiding's learning passes, then runs its largest).
  uint32_t ramp_below = 0xFFFFFFFFu;
  // > 0: within the ramp, from 4 samples until this many, each pass doubles the samples done (4, 8,
  // 16, 32, ...) instead of adding 4: a learner that folds its tables after every pass (emitter
  // guiding) then folds at 1, 2, 3, 4, 8, 16, 32, 64 samples, 8 passes where the ramp took 19 (each
  // pass a wait on the device and a fold: bench/results/emitter-guiding.md).
  uint32_t doubling_below = 0;
  // > 0: when a budget may stop the run, passes end on multiples of this and the budget is checked
  // only there (probes: a stopped run never leaves a stratified set's strata out).
  uint32_t stratified_set = 0;
  // The caller cuts the last pass of a time budget itself (the per-bounce mode, layer by layer, down
  // to a part of the texels): when less than one sample's time is left the scheduler hands out a
  // pass of one sample instead of stopping, and stops only once the budget is spent.
  bool caller_cuts_last_pass = false;
};

class PassScheduler {
 public:
  PassScheduler(const IntegratorSettings& settings, PassPolicy policy);

  // The next pass's samples [begin, begin + count); false when the bake is done. Under a time budget
  // (outside stratified sets) a pass is cut to what the budget has left at the last pass's cost per
  // sample, and the run stops when less than half a sample's time is left (without `fraction`) or
  // less than 2 % of a sample's time: it ends near the budget instead of overrunning by a pass.
  // A backend that can run a sample over part of its items passes `fraction`: the last pass of a
  // time budget may then be one sample over that fraction of the items (else `fraction` is 1), so
  // the run ends within a small part of a one-sample pass of the budget.
  // With settings.work_share over several ranks, every rank gets rank 0's decision (its clock alone
  // decides a time budget's cuts), so all run the same passes.
  bool next_pass(uint32_t& begin, uint32_t& count, double* fraction = nullptr);
  // Reports the pass just run (progress callback) and decides whether the bake stops here: at the
  // sample cap, at the time budget, or when `all_converged` (the integrator's target-error test).
  void finish_pass(uint64_t rays_so_far, bool all_converged = false);

  // Replaces the sample cap (an adaptive plan knows its total only after the pilot); progress follows it.
  void set_sample_limit(uint32_t limit) { limit_ = limit; }

  uint32_t samples_done() const { return done_; }
  // On settings.budget_clock when given.
  double elapsed_seconds() const;
  bool timed() const { return settings_.time_budget_seconds > 0; }

 private:
  bool next_pass_here(uint32_t& begin, uint32_t& count, double* fraction);

  const IntegratorSettings& settings_;
  PassPolicy policy_;
  uint32_t limit_;
  uint32_t done_ = 0;
  uint32_t pending_ = 0;  // samples of the pass handed out by next_pass
  double pending_fraction_ = 1;  // of the items that pass covers
  double pass_start_seconds_ = 0;
  double seconds_per_sample_ = 0;  // of the last pass: sizes the next one to what the budget has left
  bool stopped_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace exitance
