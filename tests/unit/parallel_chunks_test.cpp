// for_each_chunk (runtime/core/parallel_chunks.h) on its pool of workers: every index once, from
// many callers at once, nested loops (run serially inside a chunk), and a body's exception reaching
// the caller after every chunk ended, the pool usable afterwards; a loop ends while every worker
// is busy.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
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

// Every worker is held by one loop's chunks; a loop from another thread still ends, its caller
// running the chunks no worker is free to take (before, it waited for a worker).
TEST(ParallelChunks, ALoopEndsWhileEveryWorkerIsBusy) {
  const size_t threads = std::max<size_t>(std::thread::hardware_concurrency(), 1);
  if (threads < 2) GTEST_SKIP() << "one hardware thread: loops run on the caller";
  std::atomic<size_t> held{0};
  std::atomic<bool> release{false};
  auto holding = std::async(std::launch::async, [&] {
    for_each_chunk(threads, [&](size_t, size_t) {
      held.fetch_add(1);
      while (!release.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }, 1);
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (held.load() < threads && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_EQ(held.load(), threads) << "the holding loop's chunks did not all start";
  std::atomic<size_t> sum{0};
  auto other = std::async(std::launch::async, [&] {
    for_each_chunk(1000, [&](size_t begin, size_t end) { sum.fetch_add(end - begin); }, 1);
  });
  const bool ended = other.wait_for(std::chrono::seconds(20)) == std::future_status::ready;
  release.store(true);  // bounded either way: the held workers go free
  holding.get();
  other.get();
  EXPECT_TRUE(ended) << "the loop waited for a busy worker";
  EXPECT_EQ(sum.load(), 1000u);
}

}  // namespace
}  // namespace exitance
