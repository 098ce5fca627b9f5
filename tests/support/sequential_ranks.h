// The ranks of one split run (core/work_share.h) in one process, one after another, rank 0 last:
// what each other rank's gather_pieces_to_root sends is kept, call by call, and rank 0's calls receive it
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
    std::vector<std::vector<std::vector<char>>> sent;  // per gather call, per rank: its pieces packed
  };
  SequentialRanks(World& world, int rank, int ranks) : world_(world), rank_(rank), ranks_(ranks) {}
  int rank() const override { return rank_; }
  int ranks() const override { return ranks_; }
  void allgather_ranges(void*, const std::vector<size_t>&) override {
    throw std::logic_error("SequentialRanks: an allgather needs the ranks at once");
  }
  void gather_pieces_to_root(const void* own, void* whole, const std::vector<std::vector<BytePiece>>& pieces) override {
    if (world_.sent.size() <= calls_) world_.sent.resize(calls_ + 1);
    std::vector<std::vector<char>>& sent = world_.sent[calls_++];
    sent.resize(pieces.size());
    if (rank_ != 0) {
      size_t bytes = 0;
      for (const BytePiece& p : pieces[size_t(rank_)]) bytes += p.size;
      const char* from = static_cast<const char*>(own);
      sent[size_t(rank_)].assign(from, from + bytes);
      return;
    }
    for (size_t r = 1; r < pieces.size(); ++r) {
      const char* from = sent[r].data();
      for (const BytePiece& p : pieces[r]) std::memcpy(static_cast<char*>(whole) + p.offset, from, p.size), from += p.size;
    }
  }
  void broadcast(void*, size_t) override {}
  uint64_t sum(uint64_t value) override { return value; }

 private:
  World& world_;
  int rank_, ranks_;
  size_t calls_ = 0;
};

}  // namespace exitance::testing
