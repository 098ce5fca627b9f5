// A parallel loop's share done, reported through a progress callback that is not thread-safe
// (the terminal bar): workers add the items they finished, and whichever finds the lock free
// reports, at most once per 1 % and never going backwards. No callback: nothing is counted.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <mutex>
#include <utility>

namespace exitance {

using FractionDone = std::function<void(double fraction)>;

class ParallelProgress {
 public:
  ParallelProgress(FractionDone report, size_t total)
      : report_(std::move(report)), total_(total), step_(std::max<size_t>(1, total / 100)) {}

  void add(size_t items) {
    if (!report_ || total_ == 0) return;
    const size_t done = done_.fetch_add(items, std::memory_order_relaxed) + items;
    if (done / step_ == (done - items) / step_) return;  // no new percent
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || done <= reported_) return;
    reported_ = done;
    report_(double(std::min(done, total_)) / double(total_));
  }

 private:
  FractionDone report_;
  size_t total_, step_;
  std::atomic<size_t> done_{0};
  std::mutex mutex_;
  size_t reported_ = 0;  // guarded by mutex_
};

}  // namespace exitance
