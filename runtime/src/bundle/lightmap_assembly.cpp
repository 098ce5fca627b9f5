#include "exitance/runtime/bundle/lightmap_assembly.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/grouped_indices.h"
#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance {

namespace {

// Row y's cells as bits (bit b of word w is cell x = 64 w + b; bits past the width stay 0).
struct RowBits {
  size_t words = 0;
  std::vector<uint64_t> bits;
  uint64_t* row(size_t y) { return bits.data() + y * words; }
  const uint64_t* row(size_t y) const { return bits.data() + y * words; }
};

RowBits row_bits(size_t width, size_t height, const uint8_t* cells) {
  RowBits r;
  r.words = (width + 63) / 64;
  r.bits.assign(r.words * height, 0);
  for_each_chunk(height, [&](size_t first, size_t end) {
    for (size_t y = first; y < end; ++y) {
      uint64_t* out = r.row(y);
      const uint8_t* in = cells + y * width;
      for (size_t x = 0; x < width; ++x)
        if (in[x]) out[x >> 6] |= uint64_t(1) << (x & 63);
    }
  }, 64);
  return r;
}

// Cells of row y with a filled 8-neighbour (or filled themselves), word w.
uint64_t near_filled(const RowBits& filled, size_t height, size_t y, size_t w) {
  uint64_t near = 0;
  for (size_t r = (y > 0 ? y - 1 : 0); r <= y + 1 && r < height; ++r) {
    const uint64_t* row = filled.row(r);
    const uint64_t m = row[w];
    const uint64_t from_left = (m << 1) | (w > 0 ? row[w - 1] >> 63 : 0);
    const uint64_t from_right = (m >> 1) | (w + 1 < filled.words ? row[w + 1] << 63 : 0);
    near |= m | from_left | from_right;
  }
  return near;
}

// The ring-by-ring fill of dilate_into; `fillable` null: every cell. Each pass visits only the cells
// with a filled 8-neighbour (found 64 at a time on bit rows), so a pass costs the page's words plus
// its ring, not a 3x3 look at every empty cell of the page (90 % of a city page's cells).
void dilate_where(int width, int height, std::vector<uint8_t> filled, const std::vector<uint8_t>* fillable,
                  std::vector<float*> channels, int passes) {
  if (width <= 0 || height <= 0) return;
  const size_t w_cells = size_t(width), rows = size_t(height);
  // Each pass reads the state the previous one left (what it fills is applied after the whole page
  // is scanned), so rows can be scanned in parallel: each chunk of rows keeps its own list, and the
  // lists are applied after every chunk is done. Per texel, the same sums in the same order.
  const size_t channel_count = channels.size();
  RowBits filled_bits = row_bits(w_cells, rows, filled.data());
  RowBits fillable_bits;
  if (fillable) fillable_bits = row_bits(w_cells, rows, fillable->data());
  const uint64_t last_word_mask = (w_cells & 63) ? (uint64_t(1) << (w_cells & 63)) - 1 : ~uint64_t(0);
  struct Fill {
    std::vector<size_t> newly;
    std::vector<float> values;
  };
  const size_t chunks = std::clamp<size_t>(rows / 8, 1, std::max<size_t>(std::thread::hardware_concurrency(), 1));
  const size_t per_chunk = (rows + chunks - 1) / chunks;
  std::vector<Fill> fills(chunks);
  for (int pass = 0; passes < 0 || pass < passes; ++pass) {
    for_each_chunk(
        chunks,
        [&](size_t first_chunk, size_t end_chunk) {
          for (size_t chunk = first_chunk; chunk < end_chunk; ++chunk) {
            Fill& fill = fills[chunk];
            fill.newly.clear();
            fill.values.clear();
            const size_t y_end = std::min(rows, (chunk + 1) * per_chunk);
            for (size_t y = chunk * per_chunk; y < y_end; ++y)
              for (size_t w = 0; w < filled_bits.words; ++w) {
                uint64_t candidates = near_filled(filled_bits, rows, y, w) & ~filled_bits.row(y)[w];
                candidates &= fillable ? fillable_bits.row(y)[w] : (w + 1 == filled_bits.words ? last_word_mask : ~uint64_t(0));
                for (; candidates; candidates &= candidates - 1) {
                  const int x = int(w * 64 + size_t(std::countr_zero(candidates)));
                  const size_t i = y * w_cells + size_t(x);
                  // The filled neighbours in row order, then each channel summed over them in that
                  // order: per channel the same additions as one neighbour at a time.
                  size_t from[8];
                  int n = 0;
                  for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                      const int nx = x + dx, ny = int(y) + dy;
                      if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
                      const size_t j = size_t(ny) * w_cells + size_t(nx);
                      if (filled[j]) from[n++] = j;
                    }
                  if (n == 0) continue;
                  fill.newly.push_back(i);
                  for (size_t c = 0; c < channel_count; ++c) {
                    const float* channel = channels[c];
                    double sum = 0.0;
                    for (int k = 0; k < n; ++k) sum += channel[from[k]];
                    fill.values.push_back(float(sum / n));
                  }
                }
              }
          }
        },
        1);
    bool any = false;
    for (const Fill& fill : fills) any = any || !fill.newly.empty();
    if (!any) break;
    // Chunks own whole rows, so each writes only its own bit words.
    for_each_chunk(
        chunks,
        [&](size_t first_chunk, size_t end_chunk) {
          for (size_t chunk = first_chunk; chunk < end_chunk; ++chunk) {
            const Fill& fill = fills[chunk];
            for (size_t k = 0; k < fill.newly.size(); ++k) {
              const size_t i = fill.newly[k];
              filled[i] = 1;
              const size_t y = i / w_cells, x = i % w_cells;
              filled_bits.row(y)[x >> 6] |= uint64_t(1) << (x & 63);
              for (size_t c = 0; c < channel_count; ++c) channels[c][i] = fill.values[k * channel_count + c];
            }
          }
        },
        1);
  }
}

}  // namespace

void dilate_into_gutter(int width, int height, const std::vector<float>& coverage, std::vector<float*> channels,
                        int passes) {
  std::vector<uint8_t> filled(coverage.size());
  for (size_t i = 0; i < coverage.size(); ++i) filled[i] = coverage[i] > 0 ? 1 : 0;
  dilate_where(width, height, std::move(filled), nullptr, std::move(channels), passes);
}

void dilate_into(int width, int height, std::vector<uint8_t> filled, const std::vector<uint8_t>& fillable,
                 std::vector<float*> channels, int passes) {
  dilate_where(width, height, std::move(filled), &fillable, std::move(channels), passes);
}

formats::LightmapImage read_atlas_page(const std::string& path, const TexelGBuffer& gbuffer, size_t page) {
  formats::LightmapImage image = formats::read_lightmap_exr(path);
  const AtlasPage& atlas = gbuffer.pages.at(page);
  if (image.width != atlas.width || image.height != atlas.height)
    throw std::runtime_error(path + ": " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                             " pixels, but scene.bin's atlas page " + std::to_string(page) + " has " +
                             std::to_string(atlas.width) + "x" + std::to_string(atlas.height));
  return image;
}

LightmapPageAssembler::LightmapPageAssembler(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate,
                                             const AssemblyOptions& options, const std::vector<uint8_t>& untraced)
    : gbuffer_(gbuffer), estimate_(estimate), options_(options), untraced_(untraced) {
  layers_ = {"", "direct.", "indirect."};
  if (options.bounce_layers)
    for (int k = 0; k < estimate.recorded_bounces; ++k) layers_.push_back("bounce" + std::to_string(k) + ".");
  if (estimate.has_sh1())
    for (const char* axis : {"x", "y", "z"}) layers_.push_back(std::string("sh1.") + axis + ".");
  error_floor_ = estimate.error_floor();
  // The live texels of each page, in texel order.
  GroupedIndices by_page = group_indices(gbuffer.texels.size(), gbuffer.pages.size(),
                                         [&](size_t i) { return gbuffer.texels[i].page; });
  page_start_ = std::move(by_page.start);
  by_page_ = std::move(by_page.items);
}

void LightmapPageAssembler::assemble(size_t p, formats::LightmapImage& image) const {
  const AtlasPage& source = gbuffer_.pages.at(p);
  image.width = source.width;
  image.height = source.height;
  const size_t n = size_t(source.width) * size_t(source.height);
  // Zeros, in arrays reused from the image's last page where they are large enough (a page's first
  // touch of fresh memory was most of the assembly: 4.9 GB for the open city's 27 pages at once), else
  // in huge pages where the kernel allows (huge_pages.h).
  auto zeros = [n](std::vector<float>& values) {
    if (values.capacity() < n) {
      values = {};
      formats::resize_in_huge_pages(values, n);
    } else {
      values.resize(n);
      for_each_chunk(n, [&](size_t begin, size_t end) { std::fill(values.begin() + ptrdiff_t(begin), values.begin() + ptrdiff_t(end), 0.0f); });
    }
  };
  const char* names[3] = {"R", "G", "B"};
  for (const std::string& layer : layers_)
    for (const char* c : names) zeros(image.channels[layer + c]);
  {
    std::vector<float>& a = image.channels["A"];
    if (a.capacity() < n) a = {};
    formats::reserve_in_huge_pages(a, n);
    a.assign(source.coverage.begin(), source.coverage.end());
  }
  zeros(image.channels["error.Y"]);
  zeros(image.channels["valid"]);
  // The channels' arrays looked up once (not by name per texel).
  auto& channels = image.channels;
  const int width = image.width;
  float* total[3];
  float* direct[3];
  float* indirect[3];
  for (int c = 0; c < 3; ++c) {
    total[c] = channels[names[c]].data();
    direct[c] = channels[std::string("direct.") + names[c]].data();
    indirect[c] = channels[std::string("indirect.") + names[c]].data();
  }
  float* error = channels["error.Y"].data();
  float* valid = channels["valid"].data();
  std::vector<std::array<float*, 3>> bounces;
  if (options_.bounce_layers)
    for (int k = 0; k < estimate_.recorded_bounces; ++k) {
      std::array<float*, 3>& b = bounces.emplace_back();
      for (int c = 0; c < 3; ++c) b[c] = channels["bounce" + std::to_string(k) + "." + names[c]].data();
    }
  std::array<float*, 3> sh1[3] = {};
  if (estimate_.has_sh1())
    for (int axis = 0; axis < 3; ++axis)
      for (int c = 0; c < 3; ++c) sh1[axis][c] = channels[std::string("sh1.") + "xyz"[axis] + "." + names[c]].data();
  // The texels to fill from traced neighbours before the gutter is dilated.
  std::vector<uint8_t> skipped;
  const uint32_t* texels = by_page_.data() + page_start_[p];
  const size_t texel_count = page_start_[p + 1] - page_start_[p];
  if (!untraced_.empty())
    for (size_t k = 0; k < texel_count; ++k) {
      if (!untraced_[texels[k]]) continue;
      const LiveTexel& texel = gbuffer_.texels[texels[k]];
      if (skipped.empty()) skipped.assign(n, 0);
      skipped[size_t(texel.y) * size_t(width) + size_t(texel.x)] = 1;
    }
  // Every live texel writes its own cell only: the texels run in parallel.
  for_each_chunk(texel_count, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const size_t i = texels[k];
      if (!untraced_.empty() && untraced_[i]) continue;
      const LiveTexel& texel = gbuffer_.texels[i];
      const size_t at = size_t(texel.y) * size_t(width) + size_t(texel.x);
      valid[at] = 1.0f;
      const Vec3 t = estimate_.mean_total(i), d = estimate_.mean_direct(i);
      const Vec3 in = t - d;
      for (int c = 0; c < 3; ++c) {
        total[c][at] = t[c];
        direct[c][at] = d[c];
        indirect[c][at] = std::max(0.0f, in[c]);
      }
      error[at] = estimate_.relative_standard_error(i, error_floor_);
      for (size_t b = 0; b < bounces.size(); ++b) {
        const Vec3 v = estimate_.mean_bounce(int(b), i);
        for (int c = 0; c < 3; ++c) bounces[b][c][at] = v[c];
      }
      if (estimate_.has_sh1())
        for (int axis = 0; axis < 3; ++axis) {
          const Vec3 l1 = estimate_.mean_sh1(axis, i);
          for (int c = 0; c < 3; ++c) sh1[axis][c][at] = l1[c];
        }
    }
  });
  std::vector<float*> dilated;
  for (auto& [name, data] : channels)
    if (name != "A" && name != "valid") dilated.push_back(data.data());
  if (!skipped.empty()) {
    // Untraced texels from the traced ones only, as deep as the untraced region is, and only
    // across chart texels (never from another chart through the gutter).
    std::vector<uint8_t> traced(n);
    for (size_t i = 0; i < n; ++i) traced[i] = valid[i] > 0 ? 1 : 0;
    dilate_into(width, image.height, std::move(traced), skipped, dilated, -1);
  }
  dilate_into_gutter(width, image.height, source.coverage, dilated, options_.dilation_texels);
}

std::vector<formats::LightmapImage> assemble_lightmap_pages(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate,
                                                            const AssemblyOptions& options,
                                                            const std::vector<uint8_t>& untraced) {
  const LightmapPageAssembler assembler(gbuffer, estimate, options, untraced);
  std::vector<formats::LightmapImage> pages(gbuffer.pages.size());
  for (size_t p = 0; p < pages.size(); ++p) assembler.assemble(p, pages[p]);
  return pages;
}

}  // namespace exitance
