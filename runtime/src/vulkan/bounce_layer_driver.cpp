#include "bounce_layer_driver.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance_spirv/bounce_cache.h"
#include "guide_buffer.h"

namespace exitance::vulkan {
namespace {

// Per work item: result slot 0 (RGB) and the back-face flag (bindings.glsl bounce_back_face_index).
constexpr size_t kResultBytes = 16;
// Per texel, a pass's sums as read back (RGB and their squares, doubles): the largest transfer
// through the kept staging buffer (a cache's means are 16 bytes per texel).
constexpr VkDeviceSize kSumBytesPerTexel = 6 * 8;

float word_bits(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

}  // namespace

BounceLayerDriver::~BounceLayerDriver() = default;

void BounceLayerDriver::report(LightmapEstimate::EmitterGuidingReport& out) const {
  if (emitter_guide_) emitter_buffer_->report(runner_, *emitter_guide_, settings_, out);
}

BounceLayerDriver::BounceLayerDriver(WavefrontBatchRunner& runner, std::shared_ptr<const Scene> source,
                                     const TexelGBuffer& gbuffer, const IntegratorSettings& settings,
                                     std::shared_ptr<const LightingScene> lighting)
    : runner_(runner), source_(std::move(source)), gbuffer_(gbuffer), settings_(settings) {
  emitter_guide_ = emitter_guide_for_device(lighting, runner_.scene(), gbuffer, settings);
  // The tables the lookup reads (bounce_pass.glsl bounce_cache_lookup), as BounceLayerCache::lookup
  // reads them on the CPU: each triangle's instance and lightmap UVs, each instance's rectangle.
  const size_t triangles = source_ && source_->triangle_instance.size() * 3 <= source_->lightmap_uv.size()
                               ? source_->triangle_instance.size() : 0;
  const size_t instances = gbuffer_.instance_rects.size(), pages = gbuffer_.pages.size();
  const size_t triangle_table = kBounceCacheHeaderWords;
  const size_t instance_table = triangle_table + triangles * kBounceCacheTriangleWords;
  const size_t page_table = instance_table + instances * kBounceCacheInstanceWords;
  first_layer_word_ = page_table + pages * kBounceCachePageWords;
  if (emitter_guide_) {  // emitter guiding's section between the tables and the layers: it never moves
    emitter_buffer_ = std::make_unique<EmitterGuideBuffer>(*emitter_guide_, first_layer_word_);
    first_layer_word_ = emitter_buffer_->end_word();
  }
  size_t page_texels = 0;
  for (const AtlasPage& page : gbuffer_.pages) page_texels += size_t(page.width) * size_t(page.height);
  layer_words_ = page_texels * kBounceCacheTexelWords;
  if (first_layer_word_ + layer_words_ >= (size_t(1) << 32))
    throw std::runtime_error("Vulkan backend: --integrator bounces: the atlas is too large for the layer cache");
  cache_words_.assign(first_layer_word_, 0.0f);
  const uint32_t header[kBounceCacheHeaderWords] = {uint32_t(triangle_table), uint32_t(triangles),
                                                    uint32_t(instance_table), uint32_t(instances),
                                                    uint32_t(page_table),     uint32_t(pages),
                                                    uint32_t(first_layer_word_), uint32_t(layer_words_)};
  for (uint32_t i = 0; i < kBounceCacheHeaderWords; ++i) cache_words_[i] = word_bits(header[i]);
  for (size_t t = 0; t < triangles; ++t) {
    float* w = &cache_words_[triangle_table + t * kBounceCacheTriangleWords];
    w[0] = word_bits(source_->triangle_instance[t]);
    for (int k = 0; k < 3; ++k) w[1 + 2 * k] = source_->lightmap_uv[t * 3 + size_t(k)].x, w[2 + 2 * k] = source_->lightmap_uv[t * 3 + size_t(k)].y;
  }
  for (size_t i = 0; i < instances; ++i) {
    const InstanceRect& rect = gbuffer_.instance_rects[i];
    float* w = &cache_words_[instance_table + i * kBounceCacheInstanceWords];
    w[0] = word_bits(uint32_t(rect.page));
    for (int k = 0; k < 4; ++k) w[1 + k] = rect.scale_offset[k];
  }
  size_t first_texel = 0;
  for (size_t p = 0; p < pages; ++p) {
    float* w = &cache_words_[page_table + p * kBounceCachePageWords];
    w[0] = word_bits(uint32_t(gbuffer_.pages[p].width));
    w[1] = word_bits(uint32_t(gbuffer_.pages[p].height));
    w[2] = word_bits(uint32_t(first_texel));
    first_texel += size_t(gbuffer_.pages[p].width) * size_t(gbuffer_.pages[p].height);
  }
}

// Buffers sized and bound, the texels' start points uploaded (as LightmapDriver::prepare).
void BounceLayerDriver::prepare() {
  const size_t texels = gbuffer_.texels.size();
  if (texels >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many texels");
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  max_work_ = runner_.work_items_per_batch(kResultBytes);
  std::vector<GpuSurfacePoint> start_points(texels);
  for_each_chunk(texels, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) start_points[i] = texel_start_point(gbuffer_.texels[i]);
  });
  buffers.items.reserve(context, texels);
  buffers.texels.reserve(context, texels, 1);
  buffers.results.reserve(context, max_work_ * kResultBytes);
  runner_.bind_buffers();
  context.upload(buffers.items.start_points, start_points.data(), start_points.size() * sizeof(GpuSurfacePoint));
  buffers.items.owner = WorkItems::Owner::Texels;
  // One result slot (recorded 0): every contribution of a layer sample adds to it.
  params_ = runner_.bake_params(settings_, 0, uint32_t(texels));
  params_.directional = 0;
  params_.max_bounces = 0;
  params_.bounce_flags = kBouncePass | (settings_.trace_first_bounce ? kBounceTraceFirst : 0u);
  prepared_ = true;
}

// Layers [0, layers) on the device as the host's caches are now. The whole buffer on this bake's
// first upload (the buffer may hold an earlier bake's caches or a probe bake's SH sums) and when it
// had to grow (a new buffer), else only the layers rebuilt since.
void BounceLayerDriver::upload_caches(size_t layers, const std::vector<BounceLayerCache>& caches,
                                      const std::vector<uint64_t>& versions) {
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  const size_t words = first_layer_word_ + std::max<size_t>(layers, 1) * layer_words_;
  if (words * 4 > size_t(context.properties().limits.maxStorageBufferRange))
    throw std::runtime_error("Vulkan backend: --integrator bounces: " + std::to_string(layers) +
                             " layer caches pass the device's largest storage buffer");
  if (cache_words_.size() < words) cache_words_.resize(words, 0.0f);
  uploaded_versions_.resize(std::max(uploaded_versions_.size(), layers), 0);
  bool whole = buffers.probes.sh_sums.size() < words * 4;
  if (whole) {
    buffers.probes.reserve_bytes(context, words * 4);
    runner_.bind_buffers();
  }
  whole = whole || !tables_uploaded_;
  tables_uploaded_ = true;
  for (size_t k = 0; k < layers; ++k) {
    if (uploaded_versions_[k] == versions[k] && !whole) continue;
    caches[k].interleave(cache_words_, first_layer_word_ + k * layer_words_);
    if (settings_.inspect_bounce_cache)
      settings_.inspect_bounce_cache(k, std::vector<float>(cache_words_.begin() + std::ptrdiff_t(first_layer_word_ + k * layer_words_),
                                                           cache_words_.begin() + std::ptrdiff_t(first_layer_word_ + (k + 1) * layer_words_)));
    if (!whole && layer_words_ > 0)
      context.upload(buffers.probes.sh_sums, &cache_words_[first_layer_word_ + k * layer_words_], layer_words_ * 4,
                     (first_layer_word_ + k * layer_words_) * 4);
    uploaded_versions_[k] = versions[k];
  }
  if (whole) {
    context.upload(buffers.probes.sh_sums, cache_words_.data(), words * 4);
    upload_emitter_section();
  }
}

// Emitter guiding's section (its front tables as the cache holds them, back tables at 0) and the
// path state's room for what a vertex learns, after a whole upload of the cache buffer.
void BounceLayerDriver::upload_emitter_section() {
  if (!emitter_buffer_) return;
  if (runner_.buffers().paths.reserve_emitter_learning(runner_.context())) runner_.bind_buffers();
  emitter_buffer_->upload(runner_);
}

void BounceLayerDriver::reserve_device_layers(size_t layers) {
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  const size_t words = first_layer_word_ + std::max<size_t>(layers, 1) * layer_words_;
  const size_t limit = size_t(context.properties().limits.maxStorageBufferRange);
  if (words * 4 > limit)
    throw std::runtime_error("Vulkan backend: --integrator bounces: " + std::to_string(layers) +
                             " layer caches pass the device's largest storage buffer");
  if (!tables_uploaded_) {  // this bake's header and tables (the buffer may hold another bake's data)
    if (buffers.probes.sh_sums.size() < words * 4) {
      buffers.probes.reserve_bytes(context, words * 4);
      runner_.bind_buffers();
    }
    context.upload(buffers.probes.sh_sums, cache_words_.data(), first_layer_word_ * 4);
    upload_emitter_section();
    tables_uploaded_ = true;
    return;
  }
  const VkDeviceSize held = buffers.probes.sh_sums.size();
  if (held >= words * 4) return;
  // Twice the layers at a time (a bake adds one layer per bounce), the layers built so far copied over.
  const size_t grown = std::min(limit / 4, std::max(words, first_layer_word_ + 2 * std::max<size_t>(layers, 1) * layer_words_));
  Buffer larger = context.create_storage_buffer(VkDeviceSize(grown) * 4);
  VkCommandBuffer cmd = context.begin();
  const VkBufferCopy region{0, 0, held};
  vkCmdCopyBuffer(cmd, buffers.probes.sh_sums.handle(), larger.handle(), 1, &region);
  context.submit_and_wait(cmd);
  buffers.probes.sh_sums = std::move(larger);
  runner_.bind_buffers();
}

void BounceLayerDriver::build_cache(size_t layer, const std::vector<Vec3>& means, const std::vector<uint8_t>& valid) {
  Context& context = runner_.context();
  const size_t texels = gbuffer_.texels.size();
  if (means.size() != texels || (!valid.empty() && valid.size() != texels))
    throw std::logic_error("BounceLayerDriver::build_cache: means or validity of another G-buffer");
  reserve_device_layers(layer + 1);
  if (!cache_kernel_) {
    // Per live texel its page texel (BounceLayerCache::build skips texels off their page), position
    // and geometric normal; per page its size and first page texel; a fill flag per page texel.
    std::vector<uint32_t> first(gbuffer_.pages.size() + 1, 0);
    std::vector<uint32_t> page_words;
    for (size_t p = 0; p < gbuffer_.pages.size(); ++p) {
      const AtlasPage& page = gbuffer_.pages[p];
      first[p + 1] = first[p] + uint32_t(page.width) * uint32_t(page.height);
      page_words.insert(page_words.end(), {uint32_t(page.width), uint32_t(page.height), first[p], 0u});
    }
    page_texels_ = first.back();
    std::vector<uint32_t> words(std::max<size_t>(texels, 1) * 8, 0xFFFFFFFFu);
    for_each_chunk(texels, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        const LiveTexel& t = gbuffer_.texels[i];
        uint32_t* w = &words[i * 8];
        const bool on_page = t.page < gbuffer_.pages.size() && t.x < uint32_t(gbuffer_.pages[t.page].width) &&
                             t.y < uint32_t(gbuffer_.pages[t.page].height);
        w[0] = on_page ? first[t.page] + t.y * uint32_t(gbuffer_.pages[t.page].width) + t.x : 0xFFFFFFFFu;
        const float values[6] = {t.position.x, t.position.y, t.position.z, t.geometric_normal.x, t.geometric_normal.y,
                                 t.geometric_normal.z};
        for (int c = 0; c < 6; ++c) w[1 + c] = guide_float_bits(values[c]);
        w[7] = 0;
      }
    });
    if (page_words.empty()) page_words.assign(4, 0u);
    cache_texels_ = context.create_storage_buffer(words.size() * 4);
    context.upload(cache_texels_, words.data(), words.size() * 4);
    cache_pages_ = context.create_storage_buffer(page_words.size() * 4);
    context.upload(cache_pages_, page_words.data(), page_words.size() * 4);
    cache_means_ = context.create_storage_buffer(std::max<size_t>(texels, 1) * 16);
    cache_flags_ = context.create_storage_buffer(std::max<size_t>(page_texels_, 1) * 4);
    cache_kernel_ = std::make_unique<ComputeKernel>(context, std::vector<VkDescriptorType>(5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER),
                                                    uint32_t(5 * 4), spirv_bounce_cache, sizeof(spirv_bounce_cache), 1,
                                                    "bounce_cache.comp");
  }
  // Means and validity packed straight into the kept staging mapping, on all cores.
  context.keep_staging(staging_, texels * kSumBytesPerTexel);  // the passes' read-backs' size: made once
  context.write_ranges(cache_means_, {{0, VkDeviceSize(texels) * sizeof(Vec4)}}, [&](char* mapped) {
    Vec4* packed = reinterpret_cast<Vec4*>(mapped);
    for_each_chunk(texels, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i)
        packed[i] = Vec4(means[i].x, means[i].y, means[i].z, valid.empty() || valid[i] ? 1.0f : 0.0f);
    });
  }, &staging_);
  // The cache buffer may have grown since the descriptors were written.
  const std::array<VkDescriptorBufferInfo, 5> infos{{{runner_.buffers().probes.sh_sums.handle(), 0, VK_WHOLE_SIZE},
                                                     {cache_texels_.handle(), 0, VK_WHOLE_SIZE},
                                                     {cache_means_.handle(), 0, VK_WHOLE_SIZE},
                                                     {cache_flags_.handle(), 0, VK_WHOLE_SIZE},
                                                     {cache_pages_.handle(), 0, VK_WHOLE_SIZE}}};
  cache_kernel_->write_buffers(0, infos.data(), uint32_t(infos.size()));
  struct Push {
    uint32_t mode, layer_word, count, ring, page_count;
  };
  const uint32_t layer_word = uint32_t(first_layer_word_ + layer * layer_words_);
  VkCommandBuffer cmd = context.begin();
  writes_visible_to_compute(cmd);
  cache_kernel_->bind(cmd, 0);
  auto dispatch = [&](uint32_t mode, size_t count, uint32_t ring) {
    if (count == 0) return;
    const Push push{mode, layer_word, uint32_t(count), ring, uint32_t(gbuffer_.pages.size())};
    cache_kernel_->push(cmd, &push, sizeof(push));
    const size_t groups = (count + 63) / 64;
    const uint32_t x = uint32_t(std::min<size_t>(groups, 65535));
    vkCmdDispatch(cmd, x, uint32_t((groups + x - 1) / x), 1);
    writes_visible_to_compute(cmd);
  };
  dispatch(0, page_texels_, 0);
  dispatch(1, texels, 0);
  for (uint32_t ring = 1; ring <= kBounceCacheDilation; ++ring) dispatch(2, page_texels_, ring);
  compute_done_before_all(cmd);
  context.submit_and_wait(cmd);
  if (settings_.inspect_bounce_cache) {
    std::vector<float> words(layer_words_);
    if (!words.empty()) context.download(runner_.buffers().probes.sh_sums, words.data(), words.size() * 4, size_t(layer_word) * 4);
    settings_.inspect_bounce_cache(layer, words);
  }
}

void BounceLayerDriver::estimate(const BounceLayerPass& pass, const std::vector<BounceLayerCache>& caches,
                                 const std::vector<uint64_t>& cache_versions) {
  if (pass.samples == 0 || pass.end <= pass.begin) return;
  if (!prepared_) prepare();
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  // Emitter guiding: the previous passes' learning becomes this pass's front table (as the CPU's
  // estimator), before any whole upload of the cache buffer could clear its back tables.
  // On the device unless asked otherwise or while the host builds the layer caches (a whole upload
  // of the cache buffer then rewrites the section from the cache).
  if (emitter_guide_ && learned_samples_ > 0 && emitter_guide_->active()) {
    if (settings_.guide_fold_on_host || settings_.bounce_caches_on_host) {
      emitter_buffer_->fold_learning_on_host(runner_, *emitter_guide_, learned_samples_);
    } else {
      if (!emitter_fold_) emitter_fold_ = std::make_unique<GuideFoldKernel>(runner_.context(), GuideFold::Emitter);
      emitter_buffer_->fold_learning(runner_, *emitter_fold_, *emitter_guide_, learned_samples_);
    }
  }
  if (builds_caches())
    reserve_device_layers(size_t(pass.layer));  // the layers below pass.layer were built there
  else
    upload_caches(size_t(pass.layer), caches, cache_versions);
  if (emitter_guide_) {
    learned_samples_ = std::max(learned_samples_, pass.first_sample + pass.samples);
    params_.emitter_guide = emitter_guide_->active() ? emitter_buffer_->params_offset() : 0u;
  }
  if (uint64_t(pass.first_sample) + pass.samples > std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument("Vulkan backend: more than 2^32 - 1 samples per texel");
  const size_t texels = gbuffer_.texels.size();
  // The kernels take any list of texels (as the Vulkan path tracer's target error does): a partial
  // pass runs the listed ones only.
  if (pass.texels) {
    if (pass.texels->empty()) return;
    work_list_ = *pass.texels;
  } else {
    work_list_.resize(pass.end - pass.begin);
    for (size_t i = pass.begin; i < pass.end; ++i) work_list_[i - pass.begin] = uint32_t(i);
  }
  context.upload(buffers.items.batch_items, work_list_.data(), work_list_.size() * 4);
  VkCommandBuffer cmd = context.begin();
  buffers.texels.clear(cmd);
  context.submit_and_wait(cmd);

  params_.bounce_layer = uint32_t(pass.layer);
  const size_t chunk = std::min(work_list_.size(), max_work_);
  const uint32_t largest = uint32_t(std::max<size_t>(1, max_work_ / chunk));
  for (uint32_t done = 0; done < pass.samples;) {
    const uint32_t samples = std::min(pass.samples - done, largest);
    for (size_t offset = 0; offset < work_list_.size(); offset += chunk) {
      const uint32_t n = uint32_t(std::min(chunk, work_list_.size() - offset));
      BatchTotals batch;
      runner_.run(params_, {uint32_t(offset), n, pass.first_sample + done, samples}, kResultBytes, kTexelBatch, batch);
      totals_.add(batch);
    }
    done += samples;
  }
  runner_.record_statistics(totals_, kTexelBatch);

  // The pass's sums (texel order, doubles) onto the layer's, read from the pinned staging buffer
  // kept for them (a new 48 MB one per pass at 1 M texels cost its allocation and page faults), each
  // listed texel's own entries on all cores; the back-face counts in the first bounce slot, read
  // back only where the pass counts them (B_0).
  const VkDeviceSize sum_bytes = texels * kSumBytesPerTexel;
  context.keep_staging(staging_, sum_bytes);
  context.read_back_ranges(buffers.texels.sums, {{0, sum_bytes}}, [&](const char* mapped) {
    const double* sums = reinterpret_cast<const double*>(mapped);
    for_each_chunk(work_list_.size(), [&](size_t begin, size_t end) {
      for (size_t w = begin; w < end; ++w) {
        const size_t i = work_list_[w];
        for (int c = 0; c < 3; ++c) {
          pass.sum[i * 3 + size_t(c)] += sums[i * 6 + size_t(c)];
          pass.sum_squared[i * 3 + size_t(c)] += sums[i * 6 + 3 + size_t(c)];
        }
        if (pass.texel_rays) pass.texel_rays[i] = 0;  // not counted per texel on the device: an even split
      }
    });
  }, &staging_);
  if (pass.back_faces)
    context.read_back_ranges(buffers.texels.bounce_sums, {{0, VkDeviceSize(texels) * 3 * 8}}, [&](const char* mapped) {
      const double* counts = reinterpret_cast<const double*>(mapped);
      for_each_chunk(work_list_.size(), [&](size_t begin, size_t end) {
        for (size_t w = begin; w < end; ++w) pass.back_faces[work_list_[w]] += uint32_t(counts[size_t(work_list_[w]) * 3]);
      });
    }, &staging_);
}

BounceGatherCounts BounceLayerDriver::counts() const {
  BounceGatherCounts c;
  c.rays = totals_.rays();
  c.gathers = totals_.bounce_gathers;
  c.texelless = totals_.bounce_texelless;
  c.back_faces = totals_.bounce_back_faces;
  c.nonfinite = totals_.nonfinite;
  return c;
}

}  // namespace exitance::vulkan
