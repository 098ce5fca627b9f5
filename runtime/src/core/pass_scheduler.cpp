#include "exitance/runtime/core/pass_scheduler.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/core/work_share.h"

namespace exitance {

PassScheduler::PassScheduler(const IntegratorSettings& settings, PassPolicy policy)
    : settings_(settings), policy_(policy), limit_(settings.spp == 0 ? 0xFFFFFFFFu : settings.spp) {
  policy_.largest_pass = std::max(policy_.largest_pass, 1u);
}

bool PassScheduler::next_pass(uint32_t& begin, uint32_t& count, double* fraction) {
  WorkShare* share = distributed(settings_.work_share);
  if (!share) return next_pass_here(begin, count, fraction);
  double local_fraction = 1;
  struct Decision {
    uint32_t more, begin, count;
    double fraction;
  } decision{};
  decision.more = next_pass_here(decision.begin, decision.count, fraction ? &local_fraction : nullptr) ? 1 : 0;
  decision.fraction = local_fraction;
  decision = agreed(*share, decision);
  if (!decision.more) {
    stopped_ = true;
    return false;
  }
  // A fraction only where the caller can run one; rank 0 offered it only then too.
  if (fraction) *fraction = decision.fraction;
  pending_fraction_ = fraction ? decision.fraction : 1;
  begin = decision.begin;
  count = pending_ = decision.count;
  return true;
}

bool PassScheduler::next_pass_here(uint32_t& begin, uint32_t& count, double* fraction) {
  if (fraction) *fraction = 1;
  pending_fraction_ = 1;
  if (stopped_ || done_ >= limit_) return false;
  uint32_t pass = std::min(limit_ - done_, policy_.largest_pass);
  if (policy_.ramp && done_ < policy_.ramp_below) {
    const uint32_t ramp_step = done_ < 4 ? 1u : (done_ < policy_.doubling_below ? done_ : (done_ < 64 ? 4u : 16u));
    pass = std::min(pass, ramp_step);
    if (done_ < policy_.doubling_below) pass = std::min(pass, policy_.doubling_below - done_);
    pass = std::min(pass, policy_.ramp_below - done_);  // the ramp's last pass ends where it stops
  }
  if (policy_.stratified_set > 0 && timed())
    pass = std::min(pass, policy_.stratified_set - done_ % policy_.stratified_set);
  pass_start_seconds_ = elapsed_seconds();
  if (timed() && policy_.stratified_set == 0 && seconds_per_sample_ > 0) {
    const double left = settings_.time_budget_seconds - pass_start_seconds_;
    const double samples_left = left / seconds_per_sample_;
    const bool spent = policy_.caller_cuts_last_pass ? !(samples_left > 0) : samples_left < (fraction ? 0.02 : 0.5);
    if (spent) {
      stopped_ = true;
      return false;
    }
    if (fraction && samples_left < 1) {
      pass = 1;
      *fraction = pending_fraction_ = samples_left;
    } else {
      pass = uint32_t(std::min<double>(pass, std::max(1.0, std::floor(samples_left))));
    }
  }
  begin = done_;
  count = pending_ = pass;
  return true;
}

double PassScheduler::elapsed_seconds() const {
  if (settings_.budget_clock) return settings_.budget_clock();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void PassScheduler::finish_pass(uint64_t rays_so_far, bool all_converged) {
  done_ += pending_;
  const double elapsed = elapsed_seconds();
  if (pending_ > 0) seconds_per_sample_ = (elapsed - pass_start_seconds_) / (double(pending_) * pending_fraction_);
  pending_ = 0;
  if (settings_.progress) {
    const double by_spp = limit_ != 0xFFFFFFFFu && limit_ > 0 ? double(done_) / double(limit_) : 0.0;
    const double by_time = timed() ? elapsed / settings_.time_budget_seconds : 0.0;
    settings_.progress(std::min(1.0, std::max(by_spp, by_time)), rays_so_far);
  }
  const bool at_set_end = policy_.stratified_set == 0 || done_ % policy_.stratified_set == 0;
  if (timed() && at_set_end && elapsed >= settings_.time_budget_seconds) stopped_ = true;
  if (all_converged) stopped_ = true;
}

}  // namespace exitance
