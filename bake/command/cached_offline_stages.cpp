#include "exitance/bake/command/cached_offline_stages.h"

#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "exitance/bake/cache/bake_cache_key.h"
#include "exitance/formats/format_error.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/texel_gbuffer_codec.h"

namespace exitance {

using json = nlohmann::json;
using Files = std::map<std::string, std::vector<uint8_t>>;

namespace {

std::vector<uint8_t> bytes_of(const json& value) {
  const std::string text = value.dump();
  return std::vector<uint8_t>(text.begin(), text.end());
}

const std::vector<uint8_t>& file(const StageEntry& entry, const std::string& name) {
  auto found = entry.files.find(name);
  if (found == entry.files.end()) throw std::runtime_error(name + " is missing");
  return found->second;
}

json json_file(const StageEntry& entry, const std::string& name) {
  const std::vector<uint8_t>& bytes = file(entry, name);
  return json::parse(bytes.begin(), bytes.end());
}

// Arrays of plain records, length-prefixed, in this machine's byte order (the cache is local).
class RecordWriter {
 public:
  template <class T>
  void array(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    const uint64_t count = values.size();
    append(&count, sizeof count);
    append(values.data(), values.size() * sizeof(T));
  }
  std::vector<uint8_t> bytes;

 private:
  void append(const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes.insert(bytes.end(), p, p + size);
  }
};

class RecordReader {
 public:
  RecordReader(const std::vector<uint8_t>& bytes, std::string name) : bytes_(bytes), name_(std::move(name)) {}
  template <class T>
  std::vector<T> array() {
    uint64_t count = 0;
    take(&count, sizeof count);
    if (count > (bytes_.size() - offset_) / sizeof(T)) throw std::runtime_error(name_ + " is truncated");
    std::vector<T> values(count);
    take(values.data(), count * sizeof(T));
    return values;
  }
  void finish() const {
    if (offset_ != bytes_.size()) throw std::runtime_error(name_ + " has trailing bytes");
  }

 private:
  void take(void* out, size_t size) {
    if (size > bytes_.size() - offset_) throw std::runtime_error(name_ + " is truncated");
    if (size) std::memcpy(out, bytes_.data() + offset_, size);
    offset_ += size;
  }
  const std::vector<uint8_t>& bytes_;
  std::string name_;
  size_t offset_ = 0;
};

// --- layout -----------------------------------------------------------------------------------
// Floats go through JSON as doubles with 17 digits: exact both ways.
Files encode_layout(const AtlasLayout& layout) {
  json rects = json::array();
  for (const InstanceRect& r : layout.rects)
    rects.push_back({r.page, r.x, r.y, r.width, r.height, r.scale_offset[0], r.scale_offset[1], r.scale_offset[2],
                     r.scale_offset[3]});
  return {{"layout.json", bytes_of({{"texel_density", layout.texel_density},
                                    {"page_sizes", layout.page_sizes},
                                    {"rects", rects},
                                    {"capped_instances", layout.capped_instances}})}};
}

AtlasLayout decode_layout(const StageEntry& entry, const Scene& scene) {
  const json j = json_file(entry, "layout.json");
  AtlasLayout layout;
  layout.texel_density = j.at("texel_density").get<float>();
  layout.page_sizes = j.at("page_sizes").get<std::vector<std::pair<int, int>>>();
  for (const json& r : j.at("rects")) {
    InstanceRect rect;
    rect.page = r.at(0), rect.x = r.at(1), rect.y = r.at(2), rect.width = r.at(3), rect.height = r.at(4);
    for (int k = 0; k < 4; ++k) rect.scale_offset[k] = r.at(5 + k).get<float>();
    layout.rects.push_back(rect);
  }
  layout.capped_instances = j.at("capped_instances").get<size_t>();
  if (layout.rects.size() != scene.instances.size()) throw std::runtime_error("layout.json does not fit the scene");
  return layout;
}

// --- G-buffer: scene.bin's texel records --------------------------------------------------------
Files encode_gbuffer(const TexelGBuffer& gbuffer, size_t unoccluded, const Scene& scene, const AtlasLayout& layout) {
  const formats::TexelGBufferRecords records = encode_texel_gbuffer(gbuffer, scene, layout);
  RecordWriter w;
  w.array(records.pages), w.array(records.texels), w.array(records.triangle_texel_size);
  w.array(records.partial_coverage), w.array(records.moved);
  return {{"texels.bin", std::move(w.bytes)}, {"gbuffer.json", bytes_of({{"unoccluded_texels", unoccluded}})}};
}

TexelGBuffer decode_gbuffer(const StageEntry& entry, const Scene& scene, const AtlasLayout& layout,
                            size_t& unoccluded) {
  RecordReader r(file(entry, "texels.bin"), "texels.bin");
  formats::TexelGBufferRecords records;
  records.pages = r.array<formats::TexelPageRecord>();
  records.texels = r.array<formats::TexelRecord>();
  records.triangle_texel_size = r.array<float>();
  records.partial_coverage = r.array<formats::PartialCoverageRecord>();
  records.moved = r.array<formats::MovedTexelRecord>();
  r.finish();
  TexelGBuffer gbuffer = decode_texel_gbuffer(records, scene);
  gbuffer.instance_rects = layout.rects;  // as the raster stage's G-buffer has them
  unoccluded = json_file(entry, "gbuffer.json").at("unoccluded_texels").get<size_t>();
  return gbuffer;
}

// --- checks and sealed texels: counts and one byte per live texel -------------------------------
void check_mask(const std::vector<uint8_t>& mask, const TexelGBuffer& gbuffer, const char* name) {
  if (mask.size() != gbuffer.texels.size()) throw std::runtime_error(std::string(name) + " does not fit the G-buffer");
}

Files encode_checks(const GeometryCheckReport& r) {
  return {{"checks.json", bytes_of({{"enclosed_texels", r.enclosed_texels},
                                    {"coplanar_texels", r.coplanar_texels},
                                    {"enclosed_lights", r.enclosed_lights},
                                    {"unsampled_emitters", r.unsampled_emitters}})},
          {"closed_texels.bin", r.closed_texels}};
}

GeometryCheckReport decode_checks(const StageEntry& entry, const TexelGBuffer& gbuffer) {
  const json j = json_file(entry, "checks.json");
  GeometryCheckReport r;
  r.enclosed_texels = j.at("enclosed_texels").get<size_t>();
  r.coplanar_texels = j.at("coplanar_texels").get<size_t>();
  r.enclosed_lights = j.at("enclosed_lights").get<std::vector<int>>();
  r.unsampled_emitters = j.at("unsampled_emitters").get<size_t>();
  r.closed_texels = file(entry, "closed_texels.bin");
  check_mask(r.closed_texels, gbuffer, "closed_texels.bin");
  return r;
}

Files encode_sealed(const SealedTexels& s) {
  return {{"sealed.json", bytes_of({{"texels", s.texels}, {"instances", s.instances}, {"candidates", s.candidates}})},
          {"sealed_texels.bin", s.sealed}};
}

SealedTexels decode_sealed(const StageEntry& entry, const TexelGBuffer& gbuffer) {
  const json j = json_file(entry, "sealed.json");
  SealedTexels s;
  s.texels = j.at("texels").get<size_t>();
  s.instances = j.at("instances").get<size_t>();
  s.candidates = j.at("candidates").get<size_t>();
  s.sealed = file(entry, "sealed_texels.bin");
  check_mask(s.sealed, gbuffer, "sealed_texels.bin");
  return s;
}

// --- octree (svo.bin) and probe positions (probes.bin) ------------------------------------------
Files encode_voxels(const VoxelizedScene& v) {
  const SvoBuildStatistics& s = v.statistics;
  return {{"svo.bin", formats::encode_svo(v.svo)},
          {"statistics.json",
           bytes_of({{"bounds_seconds", s.bounds_seconds}, {"voxelize_seconds", s.voxelize_seconds},
                     {"sort_seconds", s.sort_seconds}, {"leaves_seconds", s.leaves_seconds},
                     {"hierarchy_seconds", s.hierarchy_seconds}, {"total_seconds", s.total_seconds},
                     {"triangles_voxelized", s.triangles_voxelized}, {"triangles_skipped", s.triangles_skipped},
                     {"triangle_voxel_pairs", s.triangle_voxel_pairs}, {"leaves", s.leaves}, {"nodes", s.nodes},
                     {"bytes_per_node", s.bytes_per_node}, {"total_bytes", s.total_bytes}})}};
}

VoxelizedScene decode_voxels(const StageEntry& entry) {
  VoxelizedScene v;
  const std::vector<uint8_t>& svo = file(entry, "svo.bin");
  v.svo = formats::read_svo(svo.data(), svo.size(), "svo.bin");
  const json j = json_file(entry, "statistics.json");
  SvoBuildStatistics& s = v.statistics;
  s.bounds_seconds = j.at("bounds_seconds"), s.voxelize_seconds = j.at("voxelize_seconds");
  s.sort_seconds = j.at("sort_seconds"), s.leaves_seconds = j.at("leaves_seconds");
  s.hierarchy_seconds = j.at("hierarchy_seconds"), s.total_seconds = j.at("total_seconds");
  s.triangles_voxelized = j.at("triangles_voxelized"), s.triangles_skipped = j.at("triangles_skipped");
  s.triangle_voxel_pairs = j.at("triangle_voxel_pairs"), s.leaves = j.at("leaves"), s.nodes = j.at("nodes");
  s.bytes_per_node = j.at("bytes_per_node"), s.total_bytes = j.at("total_bytes");
  return v;
}

Files encode_probes(const ProbePlacement& p) {
  return {{"probes.bin", formats::encode_probes(p.grid)},
          {"placement.json", bytes_of({{"valid", p.valid}, {"moved", p.moved}, {"invalid", p.invalid},
                                       {"skipped", p.skipped}, {"automatic_spacing", p.automatic_spacing}})}};
}

ProbePlacement decode_probes(const StageEntry& entry) {
  ProbePlacement p;
  const std::vector<uint8_t>& grid = file(entry, "probes.bin");
  p.grid = formats::read_probes(grid.data(), grid.size(), "probes.bin");
  const json j = json_file(entry, "placement.json");
  p.valid = j.at("valid"), p.moved = j.at("moved"), p.invalid = j.at("invalid"), p.skipped = j.at("skipped");
  p.automatic_spacing = j.at("automatic_spacing");
  return p;
}

// The stage's product from the cache (its warnings given again), or computed and stored.
template <class Compute, class Decode, class Encode>
auto cached(std::optional<StageCache>& cache, json& outcomes, const char* stage, const std::string& key,
            Diagnostics& diagnostics, Compute compute, Decode decode, Encode encode) -> decltype(compute()) {
  if (!cache) return compute();
  if (std::optional<StageEntry> entry = cache->restore(stage, key, diagnostics)) {
    try {
      auto product = decode(*entry);
      for (const std::string& w : entry->warnings) diagnostics.warn(w);
      outcomes[stage] = "reused";
      return product;
    } catch (const std::exception& e) {
      cache->reject(stage, key, e.what(), diagnostics);
    }
  }
  const size_t before = diagnostics.warnings.size();
  auto product = compute();
  StageEntry entry;
  entry.warnings.assign(diagnostics.warnings.begin() + std::ptrdiff_t(before), diagnostics.warnings.end());
  outcomes[stage] = "computed";
  try {
    entry.files = encode(product);
  } catch (const formats::FormatError&) {
    return product;  // a product its codec cannot hold is computed every time
  }
  cache->store(stage, key, entry, diagnostics);
  return product;
}

}  // namespace

CachedOfflineStages::CachedOfflineStages(const Scene& scene, const BakeOptions& options) : options_(options) {
  if (options.cache_directory.empty()) return;
  cache_.emplace(options.cache_directory);
  keys_ = stage_cache_keys(scene, options, program_identity());
}

AtlasLayout CachedOfflineStages::layout(const Scene& scene, Diagnostics& diagnostics) {
  return cached(
      cache_, outcomes_, "layout", keys_.layout, diagnostics, [&] { return layout_stage(scene, options_, diagnostics); },
      [&](const StageEntry& e) { return decode_layout(e, scene); }, encode_layout);
}

TexelGBuffer CachedOfflineStages::raster(const Scene& scene, const AtlasLayout& layout, Diagnostics& diagnostics) {
  if (cache_) {
    if (std::optional<StageEntry> entry = cache_->restore("gbuffer", keys_.gbuffer, diagnostics)) {
      try {
        size_t unoccluded = 0;
        TexelGBuffer gbuffer = decode_gbuffer(*entry, scene, layout, unoccluded);
        for (const std::string& w : entry->warnings) diagnostics.warn(w);
        restored_unoccluded_ = unoccluded;
        outcomes_["gbuffer"] = "reused";
        return gbuffer;
      } catch (const std::exception& e) {
        cache_->reject("gbuffer", keys_.gbuffer, e.what(), diagnostics);
      }
    }
  }
  const size_t before = diagnostics.warnings.size();
  TexelGBuffer gbuffer = raster_stage(scene, layout, options_, diagnostics);
  raster_warnings_.assign(diagnostics.warnings.begin() + std::ptrdiff_t(before), diagnostics.warnings.end());
  return gbuffer;
}

size_t CachedOfflineStages::unocclude(const SceneForLighting& scene, TexelGBuffer& gbuffer, const AtlasLayout& layout,
                                      Diagnostics& diagnostics) {
  if (restored_unoccluded_) return *restored_unoccluded_;
  const size_t unoccluded = unocclude_stage(scene, gbuffer, options_);
  if (!cache_) return unoccluded;
  outcomes_["gbuffer"] = "computed";
  StageEntry entry;
  entry.warnings = raster_warnings_;
  try {
    entry.files = encode_gbuffer(gbuffer, unoccluded, *scene.scene, layout);
  } catch (const formats::FormatError&) {
    return unoccluded;  // a G-buffer scene.bin's records cannot hold is computed every time
  }
  cache_->store("gbuffer", keys_.gbuffer, entry, diagnostics);
  return unoccluded;
}

GeometryCheckReport CachedOfflineStages::checks(const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                                                Diagnostics& diagnostics) {
  return cached(
      cache_, outcomes_, "checks", keys_.checks, diagnostics,
      [&] { return scene_checks_stage(scene, gbuffer, options_, diagnostics); },
      [&](const StageEntry& e) { return decode_checks(e, gbuffer); }, encode_checks);
}

SealedTexels CachedOfflineStages::sealed_texels(const SceneForLighting& scene, const TexelGBuffer& gbuffer,
                                                const GeometryCheckReport& checks, Diagnostics& diagnostics) {
  return cached(
      cache_, outcomes_, "sealed_texels", keys_.sealed_texels, diagnostics,
      [&] { return sealed_texels_stage(scene, gbuffer, checks, options_); },
      [&](const StageEntry& e) { return decode_sealed(e, gbuffer); }, encode_sealed);
}

VoxelizedScene CachedOfflineStages::voxelize(const Scene& scene, const AtlasLayout& layout, Diagnostics& diagnostics) {
  return cached(
      cache_, outcomes_, "voxelize", keys_.voxelize, diagnostics, [&] { return voxelize_stage(scene, layout, options_); },
      decode_voxels, encode_voxels);
}

ProbePlacement CachedOfflineStages::place_probes(const SceneForLighting& scene, const VoxelizedScene* voxels,
                                                 Diagnostics& diagnostics) {
  return cached(
      cache_, outcomes_, "probe_placement", keys_.probe_placement, diagnostics,
      [&] { return place_probes_stage(scene, voxels, options_); }, decode_probes, encode_probes);
}

}  // namespace exitance
