// Live texels bucketed by position in a uniform grid over their bounds, so the texels near an edit
// (texels_near_change.h) are found from the cells around it instead of by a pass over every texel
// (a million texels: ~10 ms per edit on a laptop-class core otherwise). Built once per G-buffer
// (RefreshSession: at open), about 8 texels per cell. Texels an edit moves are set aside
// (`displace`): their cells no longer list them and every query visits them, until there are so many
// that the owner builds the grid again.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

class TexelGrid {
 public:
  TexelGrid() = default;
  explicit TexelGrid(const TexelGBuffer& gbuffer);
  size_t texel_count() const { return texels_.size(); }
  // The largest world_texel_size of the texels (as built; displaced texels raise it).
  float largest_texel_size() const { return largest_texel_size_; }
  // Texel i moved (to `texel`): no longer found through its cell, visited by every query instead.
  void displace(uint32_t i, const LiveTexel& texel);
  size_t displaced_count() const { return displaced_.size(); }
  // The texels of the cells that `box` grown by `margin` overlaps, as ranges of entries (entry(k)
  // for k in [first, second)): each row of cells in pieces of at most kRowPiece entries (a moved
  // block's few rows hold ~100 000), so that callers split them across threads. With displaced()
  // (which every query visits too), a superset of the texels within `margin` of the box. A
  // displaced texel is still listed in its row: skip it (is_displaced). Returns the number of
  // entries the ranges hold.
  static constexpr uint32_t kRowPiece = 4096;
  size_t candidate_rows(const WorldBox& box, float margin, std::vector<std::pair<uint32_t, uint32_t>>& rows) const;
  uint32_t entry(size_t k) const { return texels_[k]; }
  // Where entry k's texel was at the build (its position now unless displaced): read in entry
  // order, not from the G-buffer's 72-byte texels scattered over it.
  const Vec3& entry_position(size_t k) const { return positions_[k]; }
  const std::vector<uint32_t>& displaced() const { return displaced_; }
  bool is_displaced(uint32_t i) const { return !is_displaced_.empty() && is_displaced_[i]; }

 private:
  int cell_of(int axis, float p) const;
  Vec3 lo_{0, 0, 0};
  float cells_per_unit_[3] = {0, 0, 0};
  int cells_[3] = {1, 1, 1};
  std::vector<uint32_t> cell_start_;  // per cell, its first entry in texels_ (and one past the last)
  std::vector<uint32_t> texels_;      // texel indices, by cell
  std::vector<Vec3> positions_;       // their positions at the build, by cell
  std::vector<uint32_t> displaced_;   // texels moved since the build
  std::vector<uint8_t> is_displaced_;  // per texel
  float largest_texel_size_ = 0;
};

}  // namespace exitance
