// The ranks of one split run (core/work_share.h) in one process, one after another, rank 0 last:
// what each other rank's gather_to_root sends is kept, call by call, and rank 0's calls receive it
// in the same order (what MPI's sends give rank 0 at once). Sums and broadcasts are each rank's own
// value, which runs of a fixed sample count agree on.
#pragma once
#include <cstring>
#include <stdexcept>
#include <vector>

#include "exitance/runtime/core/work_share.h"

namespace exitance::testing {

class SequentialRanks final : public WorkShare {
 public:
  struct World {
    std::vector<std::vector<char>> sent;  // per gather call: every rank's bytes at its range
  };
  SequentialRanks(World& world, int rank, int ranks) : world_(world), rank_(rank), ranks_(ranks) {}
  int rank() const override { return rank_; }
  int ranks() const override { return ranks_; }
  void allgather_ranges(void*, const std::vector<size_t>&) override {
    throw std::logic_error("SequentialRanks: an allgather needs the ranks at once");
  }
  void gather_to_root(const void* own, void* received, const std::vector<size_t>& b) override {
    if (world_.sent.size() <= calls_) world_.sent.resize(calls_ + 1);
    std::vector<char>& bytes = world_.sent[calls_++];
    bytes.resize(b.back());
    if (rank_ != 0) {
      if (b[size_t(rank_) + 1] > b[size_t(rank_)]) std::memcpy(bytes.data() + b[size_t(rank_)], own, b[size_t(rank_) + 1] - b[size_t(rank_)]);
      return;
    }
    if (b.back() > b[1]) std::memcpy(static_cast<char*>(received) + b[1], bytes.data() + b[1], b.back() - b[1]);
  }
  void broadcast(void*, size_t) override {}
  uint64_t sum(uint64_t value) override { return value; }

 private:
  World& world_;
  int rank_, ranks_;
  size_t calls_ = 0;
};

}  // namespace exitance::testing
