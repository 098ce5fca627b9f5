// relight --share R/N: rank R's share of a bake split over N processes (core/work_share.h), run
// alone on this process's device. Nothing is exchanged: the other ranks' texels stay empty (as rank 0
// it writes zeros where they would arrive, the writes a real gather makes), and every decision a
// real split takes from rank 0 is this process's own. What it measures is the
// time one rank's texels take, so that a split's balance and its speed-up over one device can be
// found on a machine with a single GPU (bench/results/open-city-gpu.md).
#pragma once
#include <cstring>

#include "exitance/runtime/core/work_share.h"

namespace exitance {

class OneRankAlone final : public WorkShare {
 public:
  OneRankAlone(int rank, int ranks) : rank_(rank), ranks_(ranks) {}
  int rank() const override { return rank_; }
  int ranks() const override { return ranks_; }
  void allgather_ranges(void*, const std::vector<size_t>&) override {}
  void gather_pieces_to_root(const void*, void* whole, const std::vector<std::vector<BytePiece>>& pieces) override {
    if (rank_ != 0) return;
    for (size_t r = 1; r < pieces.size(); ++r)
      for (const BytePiece& p : pieces[r]) std::memset(static_cast<char*>(whole) + p.offset, 0, p.size);
  }
  void broadcast(void*, size_t) override {}
  uint64_t sum(uint64_t value) override { return value; }

 private:
  int rank_, ranks_;
};

}  // namespace exitance
