// One process's share of a bake split over several (bake under mpirun, issue 15 "Scale out"). The
// scene is replicated; each process estimates a contiguous range of the live texels (or probe
// origins) and the integrators exchange the per-item sums through the collectives below: after
// every pass where the next one needs them all (the CPU's re-split, the per-bounce tail, the next
// bounce's cache), else once at the end, onto rank 0 alone (Vulkan path tracing: only rank 0 writes
// the bundle). Items keep their global indices, so their random streams - and the result bits - do
// not depend on the split.
//
// The runtime stays free of MPI: this is an interface; bake/distributed implements it over MPI.
// No share (IntegratorSettings::work_share null) or one rank: the integrators run as before.
#pragma once
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace exitance {

// What one process did (stats.rank_work in the manifest).
struct RankWork {
  uint64_t texel_samples = 0;  // samples estimated (path mode) or layer samples (per-bounce mode), summed over texels
  uint64_t probe_samples = 0;  // probe rays' samples, summed over probes
  uint64_t rays = 0;           // rays this process traced
  double seconds = 0;          // spent estimating its items (not waiting for the others)
};

// A byte range [offset, offset + size) of an array.
struct BytePiece {
  size_t offset = 0, size = 0;
};

class WorkShare {
 public:
  virtual ~WorkShare() = default;
  virtual int rank() const = 0;
  virtual int ranks() const = 0;
  // In place over `data`, the same size on every rank: rank r has filled bytes
  // [byte_bounds[r], byte_bounds[r + 1]); afterwards every rank holds every range.
  virtual void allgather_ranges(void* data, const std::vector<size_t>& byte_bounds) = 0;
  // Rank r's pieces (pieces[r], byte ranges of an array every rank indexes alike) onto rank 0: rank
  // r sends them from `own`, packed in order; rank 0 receives every other rank's straight into
  // `whole` at their offsets (its own are not written; `whole` is not read on the other ranks, nor
  // `own` on rank 0). What only rank 0 needs, since it alone writes the bundle.
  virtual void gather_pieces_to_root(const void* own, void* whole, const std::vector<std::vector<BytePiece>>& pieces) = 0;
  // Rank 0's `bytes` bytes at `data` onto every rank (its decisions: pass sizes under a time budget).
  virtual void broadcast(void* data, size_t bytes) = 0;
  // The sum over ranks (exact: integers).
  virtual uint64_t sum(uint64_t value) = 0;

  RankWork work;  // this rank's, added to by the integrators
};

// The share to exchange through, or null where there is nothing to exchange (none, or one rank).
inline WorkShare* distributed(WorkShare* share) { return share && share->ranks() > 1 ? share : nullptr; }

// Item bounds [b[r], b[r + 1]) per rank, contiguous, by counted cost (`cost[i]` + 1 per item, so
// items that cost nothing are still spread): deterministic, the same on every rank. Empty `cost`:
// `items` split evenly.
std::vector<size_t> split_by_cost(size_t items, const std::vector<uint64_t>& cost, int ranks);

// Gathers the items [bounds[r], bounds[r + 1]) of `values_per_item` consecutive T each at `base`.
template <class T>
void allgather_items(WorkShare& share, T* base, size_t values_per_item, const std::vector<size_t>& bounds) {
  static_assert(std::is_trivially_copyable_v<T>);
  std::vector<size_t> bytes(bounds.size());
  for (size_t r = 0; r < bounds.size(); ++r) bytes[r] = bounds[r] * values_per_item * sizeof(T);
  share.allgather_ranges(base, bytes);
}

// Items dealt to ranks in blocks, round robin: rank r takes blocks r, r + N, r + 2N, ... of `block`
// consecutive items. Each rank's items then sample every region of the item range, so ranks get
// about equal cost without counting it: the Vulkan backend's split, whose devices do not count rays
// per item (the CPU backend re-splits contiguous ranges by counted rays after every pass).
struct InterleavedSplit {
  size_t items = 0;
  int ranks = 1;
  size_t block = 1024;  // texels: long enough runs for coherent work lists, short enough to balance
  // The items of `rank`, ascending; as runs [first, end) of consecutive items; and how many.
  std::vector<uint32_t> items_of(int rank) const;
  std::vector<std::pair<size_t, size_t>> runs_of(int rank) const;
  size_t count_of(int rank) const;
};

// An interleaved split's items onto rank 0, `values_per_item` consecutive T each. On rank 0 `data`
// is the whole array with its own items in place, and receives every other rank's run by run; on
// the others it holds their own items packed, run after run (what they send).
template <class T>
void gather_interleaved_to_root(WorkShare& share, T* data, size_t values_per_item, const InterleavedSplit& split) {
  static_assert(std::is_trivially_copyable_v<T>);
  const size_t item_bytes = values_per_item * sizeof(T);
  std::vector<std::vector<BytePiece>> pieces(size_t(split.ranks));
  for (int r = 0; r < split.ranks; ++r)
    for (const auto& [first, end] : split.runs_of(r)) pieces[size_t(r)].push_back({first * item_bytes, (end - first) * item_bytes});
  if (share.rank() == 0)
    share.gather_pieces_to_root(nullptr, data, pieces);
  else
    share.gather_pieces_to_root(data, nullptr, pieces);
}

// Every rank's `work`, on every rank, in rank order.
std::vector<RankWork> gather_rank_work(WorkShare& share);

// Rank 0's `value` on every rank.
template <class T>
T agreed(WorkShare& share, T value) {
  static_assert(std::is_trivially_copyable_v<T>);
  share.broadcast(&value, sizeof(T));
  return value;
}

}  // namespace exitance
