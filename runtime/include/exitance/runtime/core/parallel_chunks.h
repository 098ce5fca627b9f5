// A loop over [0, count) cut into one contiguous chunk per hardware thread, on std::threads: for
// the core's few data-parallel loops over millions of texels (texel_gbuffer_codec.cpp), where the
// core may not use TBB (runtime/CMakeLists.txt). `body(begin, end)` must be safe to run
// concurrently on disjoint ranges; small counts run on the calling thread.
#pragma once
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace exitance {

template <class Body>
void for_each_chunk(size_t count, Body body, size_t min_chunk = 65536) {
  const size_t threads = std::clamp<size_t>(count / std::max<size_t>(min_chunk, 1), 1,
                                            std::max<size_t>(std::thread::hardware_concurrency(), 1));
  if (threads == 1) {
    body(size_t(0), count);
    return;
  }
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  const size_t chunk = (count + threads - 1) / threads;
  for (size_t t = 1; t < threads; ++t)
    workers.emplace_back([&body, t, chunk, count] { body(std::min(count, t * chunk), std::min(count, (t + 1) * chunk)); });
  body(size_t(0), std::min(count, chunk));
  for (std::thread& w : workers) w.join();
}

}  // namespace exitance
