// What a refresh pass over a work list costs, to size passes to a millisecond budget
// (RefreshSession::refresh): a fixed part (the pass's drain and submissions) plus a part per
// texel-sample, fitted from the last two passes of different sizes; until then the last pass's cost
// per sample, fixed part included (conservative). Kept per list (a small list's passes are not a
// large one's). A pass is never sized above kMaxGrowth times the largest pass measured: a fit from
// two small passes whose sizes differ less than their times' noise can have a slope near 0 and sized
// the next pass at 738 samples for a 16 ms frame (825 ms; ajar_room at 64 texels/m on an H200).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>

namespace exitance::refresh {

struct PassCost {
  size_t texels = 0;  // the list it was measured on
  double last_work = 0, last_ms = 0;  // texel-samples and milliseconds of the last pass
  double fixed_ms = 0, ms_per_work = 0;
  double max_work = 0;  // the largest pass measured (texel-samples), on this list or the one before
  bool fitted = false, explored = false;
  // Not measured on this list yet: the cost is the last list's, a prior, whose passes get
  // kPriorShare of the time left (a list's texels can cost more per sample than the last list's:
  // the texels near an edit are not a random subset).
  bool prior = false;
  static constexpr double kPriorShare = 0.6;
  // How far beyond the largest measured pass the model may extrapolate: each larger pass measures
  // the model where it is used, so a wrong fit costs at most this factor of a measured pass.
  static constexpr double kMaxGrowth = 4.0;
  // The last list's fitted fixed part (a pass's drain and submissions, whichever its texels):
  // until this list has two pass sizes, its one measurement gives the part per texel-sample
  // beyond it (without, that part also carries the fixed cost, and the next pass is sized small).
  double known_fixed_ms = 0;

  void add(double work, double ms) {
    bool refitted = false;
    if (last_work > 0 && work != last_work) {
      const double slope = (ms - last_ms) / (work - last_work), intercept = ms - slope * work;
      if (slope > 0 && intercept >= 0) fixed_ms = intercept, ms_per_work = slope, fitted = refitted = true;
    }
    if (fitted && !refitted) {
      // No new slope (the same size again, or two sizes that give none): the fit is moved through
      // this pass, so that a fit from two noisy passes (a process's first passes, at low clocks)
      // does not hold for as long as the sizes repeat (it held the courtyard's frames after a sun
      // edit at 2 samples where 14 fit).
      const double intercept = ms - ms_per_work * work;
      if (intercept >= 0) fixed_ms = intercept;
      else fixed_ms = 0, ms_per_work = ms / work;
    }
    if (!fitted) {
      fixed_ms = ms > 2 * known_fixed_ms ? known_fixed_ms : 0;
      ms_per_work = (ms - fixed_ms) / work;
    }
    last_work = work, last_ms = ms;
    max_work = std::max(max_work, work);
    prior = false;
  }
  // The most texel-samples a pass may have now (kMaxGrowth times the largest measured; unbounded
  // before any).
  double work_cap() const { return max_work > 0 ? kMaxGrowth * max_work : INFINITY; }
  // The time a pass may take of `remaining` ms: all of it, or kPriorShare of it on a prior.
  double usable(double remaining) const { return prior ? kPriorShare * remaining : remaining; }
  // Whole samples of `texels` that fit in `remaining` ms, at most work_cap(); 0 when none.
  double fitting(double remaining, size_t texels) const {
    const double per_sample = ms_per_work * double(texels);
    if (!(per_sample > 0)) return 1.0;
    const double fit = std::floor((usable(remaining) - fixed_ms) / per_sample);
    return std::min(fit, std::max(1.0, std::floor(work_cap() / double(texels))));
  }
  // Texels of one sample that fit in `remaining` ms (a pass over part of a list), at most work_cap().
  double fitting_texels(double remaining) const {
    return std::min(std::floor((usable(remaining) - fixed_ms) / ms_per_work), std::floor(work_cap()));
  }
  // A model for another list of `list_texels`, starting from this one's cost as its prior.
  PassCost for_list(size_t list_texels) const {
    PassCost next;
    next.texels = list_texels;
    if (ms_per_work > 0) next.fixed_ms = fixed_ms, next.ms_per_work = ms_per_work, next.prior = true;
    next.known_fixed_ms = fitted ? fixed_ms : known_fixed_ms;
    next.max_work = max_work;
    return next;
  }
};

}  // namespace exitance::refresh
