// for_each_chunk (runtime/core/parallel_chunks.h) on its pool of workers: every index once, from
// many callers at once, nested loops (run serially inside a chunk), and a body's exception reaching
// the caller after every chunk ended, the pool usable afterwards.
#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <stdexcept>
#include <thread>
#include <vector>

#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance {
namespace {

TEST(ParallelChunks, EveryIndexOnce) {
  for (size_t count : {size_t(0), size_t(1), size_t(7), size_t(1000), size_t(100003)}) {
    std::vector<std::atomic<int>> seen(count);
    for_each_chunk(count, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) seen[i].fetch_add(1);
    }, 16);
    for (size_t i = 0; i < count; ++i) ASSERT_EQ(seen[i].load(), 1) << i << " of " << count;
  }
}

TEST(ParallelChunks, ManyCallersAndNestedLoops) {
  std::vector<std::thread> callers;
  std::atomic<uint64_t> total{0};
  for (int c = 0; c < 4; ++c)
    callers.emplace_back([&] {
      for (int round = 0; round < 20; ++round)
        for_each_chunk(64, [&](size_t begin, size_t end) {
          for (size_t i = begin; i < end; ++i)
            for_each_chunk(100, [&](size_t b, size_t e) { total.fetch_add(e - b); }, 10);
        }, 4);
    });
  for (std::thread& t : callers) t.join();
  EXPECT_EQ(total.load(), uint64_t(4) * 20 * 64 * 100);
}

TEST(ParallelChunks, AnExceptionReachesTheCallerAfterEveryChunk) {
  std::atomic<size_t> done{0};
  EXPECT_THROW(for_each_chunk(4096, [&](size_t begin, size_t end) {
    if (begin == 0) throw std::runtime_error("chunk 0");
    if (end == 4096) throw std::invalid_argument("last chunk");
    done.fetch_add(end - begin);
  }, 1), std::exception);
  const size_t after = done.load();
  std::atomic<size_t> again{0};
  for_each_chunk(4096, [&](size_t begin, size_t end) { again.fetch_add(end - begin); }, 1);
  EXPECT_EQ(again.load(), 4096u);
  EXPECT_EQ(done.load(), after);  // no chunk of the failed loop ran on after it returned
}

}  // namespace
}  // namespace exitance
