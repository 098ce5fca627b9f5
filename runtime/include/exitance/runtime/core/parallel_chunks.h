// A loop over [0, count) cut into one contiguous chunk per hardware thread: for the core's few
// data-parallel loops over texels and triangles (texel_gbuffer_codec.cpp, the runtime's edits),
// where the core may not use TBB (runtime/CMakeLists.txt). `body(begin, end)` must be safe to run
// concurrently on disjoint ranges; small counts run on the calling thread. The chunks run on
// workers started once per process (ChunkPool): an edit runs a dozen such loops of a few
// milliseconds, and starting 15 threads for each cost about half a millisecond on a 16-core host.
// A body that throws: the first exception is rethrown to the caller once every chunk has ended.
#pragma once
#include <algorithm>
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

  // task(k) for every k in [0, count): k = 0 on the calling thread, the others on the workers.
  void run(size_t count, const std::function<void(size_t)>& task) {
    Job job;
    job.task = &task;
    job.remaining = count - 1;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (size_t k = 1; k < count; ++k) queue_.push_back({&job, k});
    }
    if (count > 2) work_.notify_all();
    else if (count == 2) work_.notify_one();
    try {
      task(0);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!job.error) job.error = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    job.finished.wait(lock, [&] { return job.remaining == 0; });
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
    size_t remaining = 0;  // items not yet finished (under the pool's mutex)
    std::exception_ptr error;
    std::condition_variable finished;
  };
  struct Item {
    Job* job;
    size_t index;
  };

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
      work_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing left
      const Item item = queue_.front();
      queue_.pop_front();
      lock.unlock();
      std::exception_ptr error;
      try {
        (*item.job->task)(item.index);
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      if (error && !item.job->error) item.job->error = error;
      if (--item.job->remaining == 0) item.job->finished.notify_one();
    }
  }

  std::mutex mutex_;
  std::condition_variable work_;
  std::deque<Item> queue_;
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
