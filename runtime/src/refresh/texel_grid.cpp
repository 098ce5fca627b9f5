#include "exitance/runtime/refresh/texel_grid.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance {

TexelGrid::TexelGrid(const TexelGBuffer& gbuffer) {
  const size_t n = gbuffer.texels.size();
  if (n == 0) return;
  WorldBox bounds;
  for (const LiveTexel& t : gbuffer.texels) {
    bounds.grow(t.position);
    largest_texel_size_ = std::max(largest_texel_size_, t.world_texel_size);
  }
  const Vec3 extent = bounds.hi - bounds.lo;
  const float largest = std::max({extent.x, extent.y, extent.z, 1e-6f});
  // Cells of one size, about 8 texels each over the bounds' volume (a flat scene: over its area).
  double volume = 1;
  for (int a = 0; a < 3; ++a) volume *= std::max(double(extent[a]), 1e-3 * largest);
  const double cell = std::cbrt(volume / std::max(1.0, double(n) / 8.0));
  for (int a = 0; a < 3; ++a) {
    cells_[a] = int(std::clamp(std::ceil(double(extent[a]) / cell), 1.0, 1024.0));
    cells_per_unit_[a] = extent[a] > 0 ? float(cells_[a]) / extent[a] : 0.0f;
  }
  lo_ = bounds.lo;
  const size_t cell_count = size_t(cells_[0]) * size_t(cells_[1]) * size_t(cells_[2]);
  // Each texel's cell on all cores (an edit that displaced an eighth of the texels builds the grid
  // again inside its call), counted and placed on one.
  std::vector<uint32_t> cell_of_texel(n);
  for_each_chunk(n, [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i) {
      const Vec3 p = gbuffer.texels[i].position;
      cell_of_texel[i] = uint32_t((size_t(cell_of(2, p.z)) * size_t(cells_[1]) + size_t(cell_of(1, p.y))) * size_t(cells_[0]) +
                                  size_t(cell_of(0, p.x)));
    }
  }, 65536);
  cell_start_.assign(cell_count + 1, 0);
  for (uint32_t c : cell_of_texel) ++cell_start_[size_t(c) + 1];
  for (size_t c = 0; c < cell_count; ++c) cell_start_[c + 1] += cell_start_[c];
  texels_.resize(n);
  positions_.resize(n);
  std::vector<uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t i = 0; i < n; ++i) {  // ascending within a cell
    const uint32_t k = next[cell_of_texel[i]]++;
    texels_[k] = uint32_t(i);
    positions_[k] = gbuffer.texels[i].position;
  }
  is_displaced_.assign(n, 0);  // here, not at an edit's first displaced texel
}

void TexelGrid::displace(uint32_t i, const LiveTexel& texel) {
  if (i >= texels_.size()) return;
  largest_texel_size_ = std::max(largest_texel_size_, texel.world_texel_size);
  if (is_displaced_[i]) return;
  is_displaced_[i] = 1;
  displaced_.push_back(i);
}

size_t TexelGrid::candidate_rows(const WorldBox& box, float margin, std::vector<std::pair<uint32_t, uint32_t>>& rows) const {
  rows.clear();
  if (texels_.empty() || box.empty()) return 0;
  int first[3], last[3];
  for (int a = 0; a < 3; ++a) {
    first[a] = cell_of(a, box.lo[a] - margin);
    last[a] = cell_of(a, box.hi[a] + margin);
  }
  size_t entries = 0;
  for (int z = first[2]; z <= last[2]; ++z)
    for (int y = first[1]; y <= last[1]; ++y) {
      const size_t row = (size_t(z) * size_t(cells_[1]) + size_t(y)) * size_t(cells_[0]);
      const uint32_t begin = cell_start_[row + size_t(first[0])], end = cell_start_[row + size_t(last[0]) + 1];
      entries += end - begin;
      for (uint32_t piece = begin; piece < end; piece = std::min(end, piece + kRowPiece))
        rows.emplace_back(piece, std::min(end, piece + kRowPiece));
    }
  return entries;
}

int TexelGrid::cell_of(int axis, float p) const {
  const float at = (p - lo_[axis]) * cells_per_unit_[axis];
  if (!(at > 0)) return 0;  // below the bounds, or NaN
  if (!(at < float(cells_[axis]))) return cells_[axis] - 1;
  return int(at);
}

}  // namespace exitance
