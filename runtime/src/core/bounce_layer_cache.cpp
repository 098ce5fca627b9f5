#include "exitance/runtime/core/bounce_layer_cache.h"

#include <algorithm>
#include <cmath>

#include "exitance/common/bounce_gather.h"
#include "exitance/common/gpu_layout.h"
#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance {

// The cells a cache holds, and the gutter fill as a fixed map: each ring cell averages the cells
// (seeds or earlier rings) that dilate_into_gutter would average for it, in the order it sums them.
// A layer's build is then its seeds' copy and one pass over the ring cells, with the same floats as
// dilating whole pages of ten channels (which cost 2.8 GB and most of a bake's cache time on the
// open city, 85 % of whose atlas cells hold no texel).
struct BounceCachePlan {
  static constexpr uint32_t kNoSlot = UINT32_MAX;
  static constexpr uint32_t kPending = UINT32_MAX - 1;  // a cell being filled in the current ring

  struct Page {
    int width = 0, height = 0;
    size_t first_cell = 0;          // in slot_of_cell
    uint32_t ring_begin = 0, ring_end = 0;  // its ring slots (they read only this page's slots)
  };
  const TexelGBuffer* gbuffer = nullptr;
  size_t texel_count = 0;
  int dilation = 0;
  std::vector<uint8_t> valid;  // as built from
  std::vector<Page> pages;
  std::vector<uint32_t> slot_of_cell;  // every page's cells, page after page
  std::vector<uint32_t> seed_texel;    // slot s < seeds: the live texel it holds
  uint32_t seeds = 0;
  std::vector<uint32_t> source_start;  // ring slot seeds + r averages source[source_start[r] .. [r + 1])
  std::vector<uint32_t> source;
  std::vector<Vec3> position, normal;  // per slot, dilated as the colour is

  bool matches(const TexelGBuffer& g, const std::vector<uint8_t>& v, int d) const {
    return gbuffer == &g && texel_count == g.texels.size() && dilation == d && pages.size() == g.pages.size() &&
           valid == v;
  }
  size_t slots() const { return position.size(); }

  // The ring slots' values in slot order, page by page on all cores: per channel the double sum
  // over the sources in order, divided by their count, as dilate_into does.
  template <class Value>
  void fill_rings(std::vector<Value>& values) const {
    for_each_chunk(pages.size(), [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p)
        for (uint32_t slot = pages[p].ring_begin; slot < pages[p].ring_end; ++slot) {
          const uint32_t r = slot - seeds;
          const uint32_t first = source_start[r], count = source_start[r + 1] - first;
          Value v;
          for (int c = 0; c < 3; ++c) {
            double sum = 0.0;
            for (uint32_t k = 0; k < count; ++k) sum += values[source[first + k]][c];
            v[c] = float(sum / int(count));
          }
          values[slot] = v;
        }
    }, 1);
  }

  static std::shared_ptr<const BounceCachePlan> make(const TexelGBuffer& gbuffer, const std::vector<uint8_t>& valid,
                                                     int dilation) {
    auto plan = std::make_shared<BounceCachePlan>();
    plan->gbuffer = &gbuffer;
    plan->texel_count = gbuffer.texels.size();
    plan->dilation = dilation;
    plan->valid = valid;
    size_t cells = 0;
    for (const AtlasPage& source : gbuffer.pages) {
      Page& page = plan->pages.emplace_back();
      page.width = source.width, page.height = source.height;
      page.first_cell = cells;
      cells += size_t(std::max(source.width, 0)) * size_t(std::max(source.height, 0));
    }
    formats::resize_in_huge_pages(plan->slot_of_cell, cells);
    std::fill(plan->slot_of_cell.begin(), plan->slot_of_cell.end(), kNoSlot);
    // Seeds: the valid texels' cells (a cell two texels name holds the later one's, as the pages did).
    std::vector<std::vector<uint32_t>> newly(plan->pages.size());
    for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
      const LiveTexel& t = gbuffer.texels[i];
      if (t.page >= plan->pages.size()) continue;  // a hand-made G-buffer without pages: nothing to look up
      if (!valid.empty() && !valid[i]) continue;
      const Page& page = plan->pages[t.page];
      if (t.x >= uint32_t(page.width) || t.y >= uint32_t(page.height)) continue;
      const uint32_t at = t.y * uint32_t(page.width) + t.x;
      uint32_t& slot = plan->slot_of_cell[page.first_cell + at];
      if (slot == kNoSlot) {
        slot = uint32_t(plan->seed_texel.size());
        plan->seed_texel.push_back(uint32_t(i));
        newly[t.page].push_back(at);
      } else {
        plan->seed_texel[slot] = uint32_t(i);
      }
    }
    plan->seeds = uint32_t(plan->seed_texel.size());
    plan->position.resize(plan->seeds);
    plan->normal.resize(plan->seeds);
    for (uint32_t s = 0; s < plan->seeds; ++s) {
      const LiveTexel& t = gbuffer.texels[plan->seed_texel[s]];
      plan->position[s] = t.position;
      plan->normal[s] = t.geometric_normal;
    }
    plan->source_start.push_back(0);
    // Rings: a cell is filled in ring k exactly when it is unfilled and has a neighbour filled in
    // ring k - 1 (one filled earlier would have filled it then), so each ring's candidates are the
    // previous ring's unfilled neighbours; they read only cells filled before the ring.
    for (size_t p = 0; p < plan->pages.size(); ++p) {
      Page& page = plan->pages[p];
      page.ring_begin = uint32_t(plan->slots());
      uint32_t* slot_of = plan->slot_of_cell.data() + page.first_cell;
      const int w = page.width, h = page.height;
      std::vector<uint32_t> ring;
      for (int pass = 0; pass < dilation && !newly[p].empty(); ++pass) {
        ring.clear();
        for (uint32_t at : newly[p]) {
          const int x = int(at % uint32_t(w)), y = int(at / uint32_t(w));
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int nx = x + dx, ny = y + dy;
              if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
              const uint32_t j = uint32_t(ny) * uint32_t(w) + uint32_t(nx);
              if (slot_of[j] == kNoSlot) slot_of[j] = kPending, ring.push_back(j);
            }
        }
        std::sort(ring.begin(), ring.end());  // row order, as the pages were scanned
        const uint32_t first_slot = uint32_t(plan->slots());
        for (uint32_t at : ring) {
          const int x = int(at % uint32_t(w)), y = int(at / uint32_t(w));
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int nx = x + dx, ny = y + dy;
              if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
              const uint32_t s = slot_of[uint32_t(ny) * uint32_t(w) + uint32_t(nx)];
              if (s < kPending) plan->source.push_back(s);
            }
          plan->source_start.push_back(uint32_t(plan->source.size()));
        }
        for (size_t k = 0; k < ring.size(); ++k) slot_of[ring[k]] = first_slot + uint32_t(k);
        plan->position.resize(plan->position.size() + ring.size());
        plan->normal.resize(plan->normal.size() + ring.size());
        page.ring_end = uint32_t(plan->slots());
        newly[p].swap(ring);
      }
      page.ring_end = uint32_t(plan->slots());
    }
    plan->fill_rings(plan->position);
    plan->fill_rings(plan->normal);
    return plan;
  }
};

void BounceLayerCache::build(const TexelGBuffer& gbuffer, const std::vector<Vec3>& texel_values,
                             const std::vector<uint8_t>& valid, int dilation, const BounceLayerCache* plan_from) {
  if (plan_from && plan_from->plan_ && plan_from->plan_->matches(gbuffer, valid, dilation))
    plan_ = plan_from->plan_;
  else if (!plan_ || !plan_->matches(gbuffer, valid, dilation))
    plan_ = BounceCachePlan::make(gbuffer, valid, dilation);
  const BounceCachePlan& plan = *plan_;
  colour_.resize(plan.slots());
  for_each_chunk(plan.seeds, [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) colour_[s] = texel_values[plan.seed_texel[s]];
  });
  plan.fill_rings(colour_);
}

bool BounceLayerCache::lookup(const TexelGBuffer& gbuffer, uint32_t instance, Vec2 uv, Vec3 position, Vec3 normal,
                              Vec3& out) const {
  if (!plan_ || instance >= gbuffer.instance_rects.size()) return false;
  const InstanceRect& rect = gbuffer.instance_rects[instance];
  if (rect.page < 0 || size_t(rect.page) >= plan_->pages.size()) return false;
  const BounceCachePlan::Page& page = plan_->pages[size_t(rect.page)];
  const uint32_t* slot_of = plan_->slot_of_cell.data() + page.first_cell;
  const Vec4 scale_offset{rect.scale_offset[0], rect.scale_offset[1], rect.scale_offset[2], rect.scale_offset[3]};
  const BilinearFootprint f = bilinear_footprint(lightmap_page_uv(uv, scale_offset), page.width, page.height);
  double weight = 0, sum[3] = {0, 0, 0};
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      const int x = f.x0 + dx, y = f.y0 + dy;
      if (x < 0 || y < 0 || x >= page.width || y >= page.height) continue;
      const uint32_t slot = slot_of[size_t(y) * size_t(page.width) + size_t(x)];
      if (slot == BounceCachePlan::kNoSlot) continue;
      if (!texel_on_hit_surface(plan_->position[slot], plan_->normal[slot], position, normal)) continue;
      const double w = bilinear_weight(f, dx, dy);
      weight += w;
      for (int c = 0; c < 3; ++c) sum[c] += w * colour_[slot][c];
    }
  if (!(weight > kLeastFootprintWeight)) return false;
  out = {float(sum[0] / weight), float(sum[1] / weight), float(sum[2] / weight)};
  return true;
}

void BounceLayerCache::interleave(std::vector<float>& out, size_t offset) const {
  if (!plan_) return;
  static_assert(kBounceCacheTexelWords == 10u, "colour, lit, position, normal");
  const std::vector<uint32_t>& slot_of = plan_->slot_of_cell;
  for_each_chunk(slot_of.size(), [&](size_t begin, size_t end) {
    for (size_t cell = begin; cell < end; ++cell) {
      float* words = out.data() + offset + cell * kBounceCacheTexelWords;
      const uint32_t slot = slot_of[cell];
      if (slot == BounceCachePlan::kNoSlot) {
        std::fill(words, words + kBounceCacheTexelWords, 0.0f);
        continue;
      }
      const Vec3 c = colour_[slot], p = plan_->position[slot], n = plan_->normal[slot];
      const float values[kBounceCacheTexelWords] = {c.x, c.y, c.z, 1.0f, p.x, p.y, p.z, n.x, n.y, n.z};
      std::copy(values, values + kBounceCacheTexelWords, words);
    }
  });
}

}  // namespace exitance
