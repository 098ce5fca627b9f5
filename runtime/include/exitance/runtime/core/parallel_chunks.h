// A loop over [0, count) cut into one contiguous chunk per hardware thread: for the core's few
// data-parallel loops over texels and triangles (texel_gbuffer_codec.cpp, the runtime's edits),
// where the core may not use TBB (runtime/CMakeLists.txt). `body(begin, end)` must be safe to run
// concurrently on disjoint ranges; small counts run on the calling thread. The chunks run on
// workers started once per process (ChunkPool): an edit runs a dozen such loops of a few
// milliseconds, and starting 15 threads for each cost about half a millisecond on a 16-core host.
// A body that throws: the first exception is rethrown to the caller once every chunk has ended.
#pragma once
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace exitance {

namespace detail {

class ChunkPool {
 public:
  static ChunkPool& instance() {
    static ChunkPool pool;
    return pool;
  }
  // Whether the calling thread is one of the pool's (a loop inside a chunk runs serially there:
  // waiting for the pool from inside it could wait for itself).
  static bool on_worker() { return worker_flag(); }
  size_t workers() const { return threads_.size(); }

  // task(k) for every k in [0, count), each k once, on the calling thread and the workers: each
  // claims the next k until none is left, so a worker slow to wake (tens of microseconds, more than
  // a small loop's chunk) leaves its chunk to whoever is free, the caller included. Which thread
  // runs a chunk never changes the chunk's range.
  void run(size_t count, const std::function<void(size_t)>& task) {
    Job job;
    job.task = &task;
    job.count = count;
    const size_t helpers = std::min(count - 1, threads_.size());
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (size_t k = 0; k < helpers; ++k) queue_.push_back(&job);
      queued_.fetch_add(helpers, std::memory_order_relaxed);
    }
    if (helpers == threads_.size()) work_.notify_all();
    else
      for (size_t k = 0; k < helpers; ++k) work_.notify_one();
    const size_t ran = claim_and_run(job);
    std::unique_lock<std::mutex> lock(mutex_);
    // Entries no worker took are dropped: every chunk is claimed already.
    const auto untaken = std::remove(queue_.begin(), queue_.end(), &job);
    queued_.fetch_sub(size_t(queue_.end() - untaken), std::memory_order_relaxed);
    queue_.erase(untaken, queue_.end());
    job.finished += ran;
    job.done.wait(lock, [&] { return job.finished == job.count && job.holders == 0; });
    if (job.error) std::rethrow_exception(job.error);
  }

  ChunkPool(const ChunkPool&) = delete;
  ChunkPool& operator=(const ChunkPool&) = delete;
  ~ChunkPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    work_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

 private:
  struct Job {
    const std::function<void(size_t)>* task = nullptr;
    size_t count = 0;
    std::atomic<size_t> next{0};  // the next chunk to claim
    size_t finished = 0;          // chunks ended (under the pool's mutex)
    size_t holders = 0;           // workers that took the job and may still claim (under the mutex)
    std::exception_ptr error;     // the first thrown (under the mutex)
    std::condition_variable done;
  };

  // Runs chunks of `job` until none is left to claim; returns how many this thread ran.
  size_t claim_and_run(Job& job) {
    size_t ran = 0;
    for (size_t k; (k = job.next.fetch_add(1, std::memory_order_relaxed)) < job.count; ++ran) {
      try {
        (*job.task)(k);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!job.error) job.error = std::current_exception();
      }
    }
    return ran;
  }

  static bool& worker_flag() {
    thread_local bool flag = false;
    return flag;
  }

  ChunkPool() {
    const size_t n = std::max<size_t>(std::thread::hardware_concurrency(), 1) - 1;
    for (size_t i = 0; i < n; ++i) threads_.emplace_back([this] { work(); });
  }

  void work() {
    worker_flag() = true;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      if (queue_.empty() && !stopping_) {
        // A while awake before sleeping: an edit's loops come tens of microseconds apart, and a
        // sleeping worker takes about 100 microseconds to wake (bench_parallel_chunks).
        lock.unlock();
        const auto until = std::chrono::steady_clock::now() + kAwake;
        while (queued_.load(std::memory_order_relaxed) == 0 && std::chrono::steady_clock::now() < until)
          std::this_thread::yield();
        lock.lock();
      }
      work_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing left
      Job* job = queue_.front();
      queue_.pop_front();
      queued_.fetch_sub(1, std::memory_order_relaxed);
      ++job->holders;
      lock.unlock();
      const size_t ran = claim_and_run(*job);
      lock.lock();
      job->finished += ran;
      --job->holders;
      if (job->finished == job->count && job->holders == 0) job->done.notify_one();
    }
  }

  std::mutex mutex_;
  std::condition_variable work_;
  std::deque<Job*> queue_;  // one entry per worker asked to help with a job
  std::atomic<size_t> queued_{0};  // queue_.size(), read without the mutex by workers staying awake
  static constexpr std::chrono::microseconds kAwake{250};
  std::vector<std::thread> threads_;
  bool stopping_ = false;
};

}  // namespace detail

template <class Body>
void for_each_chunk(size_t count, Body body, size_t min_chunk = 65536) {
  const size_t hardware = std::max<size_t>(std::thread::hardware_concurrency(), 1);
  const size_t threads = std::clamp<size_t>(count / std::max<size_t>(min_chunk, 1), 1, hardware);
  if (threads == 1 || detail::ChunkPool::on_worker()) {
    body(size_t(0), count);
    return;
  }
  const size_t chunk = (count + threads - 1) / threads;
  const std::function<void(size_t)> task = [&body, chunk, count](size_t t) {
    body(std::min(count, t * chunk), std::min(count, (t + 1) * chunk));
  };
  detail::ChunkPool::instance().run(threads, task);
}

}  // namespace exitance
