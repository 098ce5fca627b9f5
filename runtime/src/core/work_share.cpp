#include "exitance/runtime/core/work_share.h"

#include <algorithm>

namespace exitance {

std::vector<size_t> split_by_cost(size_t items, const std::vector<uint64_t>& cost, int ranks) {
  const size_t parts = size_t(ranks > 0 ? ranks : 1);
  std::vector<size_t> bounds(parts + 1, items);
  bounds[0] = 0;
  if (cost.size() != items) {
    for (size_t r = 1; r < parts; ++r) bounds[r] = items * r / parts;
    return bounds;
  }
  // 128-bit prefix sums: exact for any counts.
  unsigned __int128 total = 0;
  for (uint64_t c : cost) total += c + 1;
  unsigned __int128 prefix = 0;
  size_t r = 1;
  for (size_t i = 0; i < items && r < parts; ++i) {
    // Rank r starts at the first item whose prefix cost reaches r / parts of the total.
    while (r < parts && prefix * parts >= total * r) bounds[r++] = i;
    prefix += cost[i] + 1;
  }
  return bounds;
}

std::vector<std::pair<size_t, size_t>> InterleavedSplit::runs_of(int rank) const {
  std::vector<std::pair<size_t, size_t>> runs;
  const size_t step = block * size_t(ranks);
  for (size_t start = size_t(rank) * block; start < items; start += step) runs.emplace_back(start, std::min(items, start + block));
  return runs;
}

std::vector<uint32_t> InterleavedSplit::items_of(int rank) const {
  std::vector<uint32_t> out;
  for (const auto& [first, end] : runs_of(rank))
    for (size_t i = first; i < end; ++i) out.push_back(uint32_t(i));
  return out;
}

size_t InterleavedSplit::count_of(int rank) const {
  size_t count = 0;
  for (const auto& [first, end] : runs_of(rank)) count += end - first;
  return count;
}

std::vector<RankWork> gather_rank_work(WorkShare& share) {
  std::vector<RankWork> all(size_t(share.ranks()));
  all[size_t(share.rank())] = share.work;
  std::vector<size_t> bounds(all.size() + 1);
  for (size_t r = 0; r < bounds.size(); ++r) bounds[r] = r;
  allgather_items(share, all.data(), 1, bounds);
  return all;
}

}  // namespace exitance
