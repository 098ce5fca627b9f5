#include "exitance/runtime/core/bounce_layer_cache.h"

#include <algorithm>
#include <cmath>

#include "exitance/common/bounce_gather.h"
#include "exitance/common/gpu_layout.h"
#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/grouped_indices.h"
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

  // A page's slots: its seeds [first_slot, ring_begin), then its rings [ring_begin, ring_end), which
  // read only the page's own slots.
  struct Page {
    int width = 0, height = 0;
    size_t first_cell = 0;  // in slot_of_cell
    uint32_t first_slot = 0, ring_begin = 0, ring_end = 0;
  };
  const TexelGBuffer* gbuffer = nullptr;
  size_t texel_count = 0;
  int dilation = 0;
  std::vector<uint8_t> valid;  // as built from
  std::vector<Page> pages;
  std::vector<uint32_t> slot_of_cell;  // every page's cells, page after page
  std::vector<uint32_t> seed_texel;    // per seed slot: the live texel it holds
  std::vector<uint32_t> source_start;  // ring slot s averages source[source_start[s] .. source_start[s + 1])
  std::vector<uint32_t> source;
  std::vector<Vec3> position, normal;  // per slot, dilated as the colour is

  bool matches(const TexelGBuffer& g, const std::vector<uint8_t>& v, int d) const {
    return gbuffer == &g && texel_count == g.texels.size() && dilation == d && pages.size() == g.pages.size() &&
           valid == v;
  }
  size_t slots() const { return position.size(); }

  // Seed slots from `seed_value(texel)`, then the ring slots in slot order, page by page on all
  // cores: per channel the double sum over the sources in order, divided by their count, as
  // dilate_into does.
  template <class Value, class SeedValue>
  void fill(std::vector<Value>& values, const SeedValue& seed_value) const {
    for_each_chunk(pages.size(), [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        for (uint32_t slot = pages[p].first_slot; slot < pages[p].ring_begin; ++slot) values[slot] = seed_value(seed_texel[slot]);
        for (uint32_t slot = pages[p].ring_begin; slot < pages[p].ring_end; ++slot) {
          const uint32_t first = source_start[slot], count = source_start[slot + 1] - first;
          Value v;
          for (int c = 0; c < 3; ++c) {
            double sum = 0.0;
            for (uint32_t k = 0; k < count; ++k) sum += values[source[first + k]][c];
            v[c] = float(sum / int(count));
          }
          values[slot] = v;
        }
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
      page.width = std::max(source.width, 0), page.height = std::max(source.height, 0);
      page.first_cell = cells;
      cells += size_t(page.width) * size_t(page.height);
    }
    formats::resize_in_huge_pages(plan->slot_of_cell, cells);
    for_each_chunk(cells, [&](size_t begin, size_t end) {
      std::fill(plan->slot_of_cell.begin() + ptrdiff_t(begin), plan->slot_of_cell.begin() + ptrdiff_t(end), kNoSlot);
    });
    // The valid texels of each page, in texel order (a hand-made G-buffer without pages, or a texel
    // off its page: nothing to look up).
    const size_t page_count = plan->pages.size();
    const GroupedIndices seeds_by_page = group_indices(gbuffer.texels.size(), page_count, [&](size_t i) {
      const LiveTexel& t = gbuffer.texels[i];
      const bool seeds = t.page < page_count && (valid.empty() || valid[i]) && t.x < uint32_t(plan->pages[t.page].width) &&
                         t.y < uint32_t(plan->pages[t.page].height);
      return seeds ? size_t(t.page) : page_count;
    });
    const std::vector<uint32_t>& page_start = seeds_by_page.start;
    const std::vector<uint32_t>& by_page = seeds_by_page.items;
    // Per page on all cores, slots numbered from 0 within the page: its seeds (a cell two texels
    // name holds the later one's, as the pages did), then its rings. A cell is filled in ring k
    // exactly when it is unfilled and has a neighbour filled in ring k - 1 (one filled earlier would
    // have filled it then), so each ring's candidates are the previous ring's unfilled neighbours;
    // they read only cells filled before the ring.
    struct Local {
      std::vector<uint32_t> seed_texel, source_start, source;
      uint32_t slots = 0;
    };
    std::vector<Local> local(page_count);
    for_each_chunk(page_count, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        Local& l = local[p];
        const int w = plan->pages[p].width, h = plan->pages[p].height;
        uint32_t* slot_of = plan->slot_of_cell.data() + plan->pages[p].first_cell;
        std::vector<uint32_t> newly, ring;
        for (uint32_t e = page_start[p]; e < page_start[p + 1]; ++e) {
          const LiveTexel& t = gbuffer.texels[by_page[e]];
          const uint32_t at = t.y * uint32_t(w) + t.x;
          if (slot_of[at] == kNoSlot) {
            slot_of[at] = uint32_t(l.seed_texel.size());
            l.seed_texel.push_back(by_page[e]);
            newly.push_back(at);
          } else {
            l.seed_texel[slot_of[at]] = by_page[e];
          }
        }
        l.slots = uint32_t(l.seed_texel.size());
        for (int pass = 0; pass < dilation && !newly.empty(); ++pass) {
          ring.clear();
          for (uint32_t at : newly) {
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
          for (uint32_t at : ring) {
            const int x = int(at % uint32_t(w)), y = int(at / uint32_t(w));
            l.source_start.push_back(uint32_t(l.source.size()));
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const int nx = x + dx, ny = y + dy;
                if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                const uint32_t s = slot_of[uint32_t(ny) * uint32_t(w) + uint32_t(nx)];
                if (s < kPending) l.source.push_back(s);
              }
          }
          for (uint32_t at : ring) slot_of[at] = l.slots++;
          newly.swap(ring);
        }
      }
    }, 1);
    // The pages' slots one after another: local numbers become global ones.
    uint32_t slots = 0, sources = 0;
    std::vector<uint32_t> first_source(page_count);
    for (size_t p = 0; p < page_count; ++p) {
      Page& page = plan->pages[p];
      page.first_slot = slots;
      page.ring_begin = slots + uint32_t(local[p].seed_texel.size());
      page.ring_end = slots + local[p].slots;
      first_source[p] = sources;
      slots += local[p].slots;
      sources += uint32_t(local[p].source.size());
    }
    plan->seed_texel.assign(slots, 0);
    plan->source_start.assign(size_t(slots) + 1, sources);
    plan->source.resize(sources);
    plan->position.resize(slots);
    plan->normal.resize(slots);
    for_each_chunk(page_count, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        const Page& page = plan->pages[p];
        const Local& l = local[p];
        std::copy(l.seed_texel.begin(), l.seed_texel.end(), plan->seed_texel.begin() + page.first_slot);
        std::fill(plan->source_start.begin() + page.first_slot, plan->source_start.begin() + page.ring_begin, first_source[p]);
        for (size_t r = 0; r < l.source_start.size(); ++r) plan->source_start[page.ring_begin + r] = first_source[p] + l.source_start[r];
        for (size_t k = 0; k < l.source.size(); ++k) plan->source[first_source[p] + k] = page.first_slot + l.source[k];
        uint32_t* slot_of = plan->slot_of_cell.data() + page.first_cell;
        const size_t page_cells = size_t(page.width) * size_t(page.height);
        for (size_t c = 0; c < page_cells; ++c)
          if (slot_of[c] != kNoSlot) slot_of[c] += page.first_slot;
      }
    }, 1);
    plan->fill(plan->position, [&](uint32_t texel) { return gbuffer.texels[texel].position; });
    plan->fill(plan->normal, [&](uint32_t texel) { return gbuffer.texels[texel].geometric_normal; });
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
  plan.fill(colour_, [&](uint32_t texel) { return texel_values[texel]; });
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
