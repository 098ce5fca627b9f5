// What one for_each_chunk loop costs beyond its work (core/parallel_chunks.h): an edit runs a dozen
// loops of 0.05-1 ms each, so waking the pool's workers is a visible part of it on a many-core host.
// Prints, per loop size, the median wall time of the loop on the pool and of the same work on the
// calling thread alone.
//   bench_parallel_chunks [--repeat N] [--gap-us G]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "exitance/runtime/core/parallel_chunks.h"

namespace {

using Clock = std::chrono::steady_clock;

// A fixed amount of arithmetic per item (~175 ns on the 2-core VM), kept from being optimized away.
float work_item(size_t i) {
  float x = float(i) * 1e-3f;
  for (int k = 0; k < 40; ++k) x = std::sqrt(x * x + 1.0f) - 0.5f;
  return x;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"for_each_chunk's cost per loop beyond its work (core/parallel_chunks.h)"};
  int repeat = 200, gap_us = 50;
  app.add_option("--repeat", repeat, "loops timed per size")->check(CLI::PositiveNumber);
  app.add_option("--gap-us", gap_us, "microseconds on the calling thread alone between loops (an edit's serial steps)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);
  std::printf("hardware threads %u, %d us between loops\n", std::thread::hardware_concurrency(), gap_us);
  std::printf("%10s %10s %12s %12s %12s\n", "items", "min_chunk", "pool us", "serial us", "ideal us");
  std::vector<float> out(1 << 20);
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  for (size_t items : {size_t(1024), size_t(4096), size_t(16384), size_t(65536), size_t(262144)}) {
    const size_t min_chunk = 256;
    std::vector<double> pool, serial;
    for (int r = 0; r < repeat; ++r) {
      auto t0 = Clock::now();
      exitance::for_each_chunk(items, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) out[i] = work_item(i + size_t(r));
      }, min_chunk);
      auto t1 = Clock::now();
      for (size_t i = 0; i < items; ++i) out[i] = work_item(i + size_t(r));
      auto t2 = Clock::now();
      pool.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
      serial.push_back(std::chrono::duration<double, std::micro>(t2 - t1).count());
      // The serial work between an edit's loops, busy on the calling thread.
      for (auto until = Clock::now() + std::chrono::microseconds(gap_us); Clock::now() < until;) {}
    }
    const double s = median(serial);
    const double ideal = s / double(std::min<size_t>(threads, std::max<size_t>(1, items / min_chunk)));
    std::printf("%10zu %10zu %12.1f %12.1f %12.1f\n", items, min_chunk, median(pool), s, ideal);
  }
  return out[12345] == 12345.0f ? 1 : 0;
}
