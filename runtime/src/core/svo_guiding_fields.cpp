// SVO guiding fields: see svo_guiding_fields.h for the choices and the device contract.
#include "exitance/runtime/core/svo_guiding_fields.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "exitance/common/rng.h"
#include "exitance/runtime/core/bvh4_closest_hit.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/runtime/svo_exitance.h"

namespace exitance {
namespace {

constexpr double kTwoPi = 6.283185307179586;
// Mean solid angle of one of the kGuideBins equal-cosine-mass hemisphere bins (the cone read uses
// the mean: bins near the horizon are wider, near the normal narrower, within a factor ~2).
constexpr double kBinSolidAngle = kTwoPi / double(kGuideBins);

Vec3 to_vec3(std::array<float, 3> a) { return {a[0], a[1], a[2]}; }

// Barycentrics (b1, b2) of p's projection onto triangle t (as bundle/texel_exitance.cpp does).
void barycentrics_on_triangle(const LightingScene& scene, uint32_t t, Vec3 p, float& b1, float& b2) {
  const Vec3 v0 = scene_triangle_vertex(scene, t, 0), v1 = scene_triangle_vertex(scene, t, 1),
             v2 = scene_triangle_vertex(scene, t, 2);
  const Vec3 e1 = v1 - v0, e2 = v2 - v0, d = p - v0;
  const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), d1 = dot(d, e1), d2 = dot(d, e2);
  const float det = d11 * d22 - d12 * d12;
  b1 = b2 = 1.0f / 3.0f;
  if (!(std::fabs(det) > 0)) return;
  b1 = std::clamp((d22 * d1 - d12 * d2) / det, 0.0f, 1.0f);
  b2 = std::clamp((d11 * d2 - d12 * d1) / det, 0.0f, 1.0f - b1);
}

// A float in [0, 1) from a hash.
float unit_float(uint64_t h) { return float(h >> 40) * 0x1.0p-24f; }

}  // namespace

double svo_guide_cone_half_angle(double solid_angle) {
  // Omega = 2 pi (1 - cos theta) for a cone of half-angle theta.
  const double cosine = 1.0 - std::clamp(solid_angle, 0.0, 2.0 * kTwoPi) / kTwoPi;
  return std::acos(std::clamp(cosine, -1.0, 1.0));
}

uint32_t svo_guide_cone_level(double solid_angle, double distance, double octree_size, uint32_t depth) {
  const double theta = svo_guide_cone_half_angle(solid_angle);
  if (!(distance > 0) || !(octree_size > 0)) return depth;
  if (!(theta < 0.5 * 3.141592653589793)) return 0;
  const double footprint_radius = distance * std::tan(theta);
  if (!(footprint_radius > 0)) return depth;
  const double level = std::floor(std::log2(octree_size / (2.0 * footprint_radius)));
  if (!(level > 0)) return 0;  // NaN too
  return level >= double(depth) ? depth : uint32_t(level);
}

SvoGuidingFields::SvoGuidingFields(const LightingScene& scene, const formats::SparseVoxelOctree& octree,
                                   const TexelGBuffer& gbuffer, const SvoGuidingConfig& config, GuideRayCast cast)
    : scene_(scene), gbuffer_(gbuffer), config_(config), cast_(std::move(cast)), octree_(octree) {
  config_.mix = std::clamp(config_.mix, 0.0f, 1.0f);
  if (!cast_) {
    cast_ = [this](Vec3 origin, Vec3 direction) {
      const BvhHit h = closest_hit(scene_, origin, direction, INFINITY);
      return GuideRayHit{h.found, h.distance, h.triangle};
    };
  }
  const size_t n = octree_.nodes.size();
  exitance_ = std::make_unique<SvoExitanceCache>(octree_);
  node_normals_.resize(n);
  node_links_.resize(2 * n);
  for (size_t i = 0; i < n; ++i) {
    const formats::SvoNode& node = octree_.nodes[i];
    node_normals_[i] = to_vec3(formats::decode_octahedral_normal(node.normal_oct));
    node_links_[2 * i] = node.first_child;
    node_links_[2 * i + 1] = uint32_t(node.child_mask) | (uint32_t(node.level) << 8);
    if (node.flags & (formats::kSvoFrontLit | formats::kSvoBackLit)) seeded_ = true;
  }
  l_min_ = octree_.depth > uint32_t(std::max(0, config_.l_min_below_depth))
               ? octree_.depth - uint32_t(std::max(0, config_.l_min_below_depth))
               : 0;
  counts_.reset(new std::atomic<uint32_t>[n * kGuideNormalClasses]);
  for (size_t i = 0; i < n * kGuideNormalClasses; ++i) counts_[i].store(0, std::memory_order_relaxed);
  node_bin_.assign(n, kNoBin);
  texel_node_.resize(gbuffer.texels.size());
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) texel_node_[i] = node_of(gbuffer.texels[i].position);
}

SvoGuidingConfig svo_guiding_config(const IntegratorSettings& settings) {
  SvoGuidingConfig config;
  config.mix = settings.guiding_mix;
  config.c_ray = settings.guiding_svo_c_ray;
  config.rays_per_bin = settings.guiding_svo_rays_per_bin;
  config.emitted = settings.guiding_svo_emitted;
  return config;
}

SvoGuidingFields::~SvoGuidingFields() = default;

uint32_t SvoGuidingFields::node_of(Vec3 p) const {
  const uint32_t node = formats::svo_find_node(octree_, {p.x, p.y, p.z}, octree_.depth);
  return node == formats::kSvoNoParent ? kNoNode : node;
}

uint32_t SvoGuidingFields::record_of(uint32_t node, Vec3 shading_normal) const {
  if (node == kNoNode) return kNoRecord;
  const uint32_t bin = node_bin_[node];
  if (bin == kNoBin) return kNoRecord;
  return record_index_[size_t(bin) * kGuideNormalClasses + guide_normal_class(shading_normal)];
}

GuideVertex SvoGuidingFields::vertex(uint32_t record) const {
  GuideVertex g = guide_vertex_cosine();
  if (record == kNoRecord) return g;
  g.guided_probability = record_front_[2 * size_t(record)];
  g.normal_class = record_class_[record];
  g.cdf = &cdf_[size_t(record) * (kGuideBins + 1)];
  return g;
}

void SvoGuidingFields::count(uint32_t node, Vec3 shading_normal) {
  if (node == kNoNode) return;
  counts_[size_t(node) * kGuideNormalClasses + guide_normal_class(shading_normal)].fetch_add(1, std::memory_order_relaxed);
}

void SvoGuidingFields::import_counts(const uint32_t* counts, size_t words) {
  const size_t n = std::min(words, octree_.nodes.size() * kGuideNormalClasses);
  for (size_t i = 0; i < n; ++i)
    if (counts[i]) counts_[i].fetch_add(counts[i], std::memory_order_relaxed);
}

void SvoGuidingFields::rebuild(const LightmapEstimate* estimate, double samples_counted, uint64_t seed) {
  if (octree_.nodes.empty()) return;
  if (estimate) fill_exitance(*estimate);
  partition(samples_counted);
  build_records(seed);
  for (size_t i = 0; i < octree_.nodes.size() * kGuideNormalClasses; ++i) counts_[i].store(0, std::memory_order_relaxed);
  ++rebuilds_;
}

void SvoGuidingFields::fill_exitance(const LightmapEstimate& estimate) {
  for (size_t i = 0; i < gbuffer_.texels.size(); ++i) {
    const LiveTexel& t = gbuffer_.texels[i];
    if (i >= estimate.texels.size() || estimate.texels[i].samples == 0) continue;
    float b1, b2;
    barycentrics_on_triangle(scene_, t.triangle, t.position, b1, b2);
    const Vec3 reflected = t.albedo * estimate.mean_total(i);
    const Vec3 outgoing = config_.emitted ? scene_emission(scene_, t.triangle, b1, b2) + reflected : reflected;
    exitance_->deposit({t.position, t.geometric_normal, outgoing * kPi, t.world_texel_size * t.world_texel_size});
  }
  exitance_->publish(1.0f);  // replacement: the running estimate already averages every sample
  exitance_->store_into(octree_);
}

void SvoGuidingFields::partition(double samples_counted) {
  const size_t n = octree_.nodes.size();
  std::vector<uint64_t> subtree(n, 0);
  std::vector<uint64_t> per_class(n * kGuideNormalClasses, 0);
  for (size_t i = 0; i < n * kGuideNormalClasses; ++i) per_class[i] = counts_[i].load(std::memory_order_relaxed);
  if (!(samples_counted > 0)) {
    // A seeded start: one vertex per texel.
    for (size_t i = 0; i < gbuffer_.texels.size(); ++i)
      if (texel_node_[i] != kNoNode)
        ++per_class[size_t(texel_node_[i]) * kGuideNormalClasses + guide_normal_class(gbuffer_.texels[i].shading_normal)];
  }
  for (size_t i = 0; i < n; ++i)
    for (uint32_t c = 0; c < kGuideNormalClasses; ++c) subtree[i] += per_class[i * kGuideNormalClasses + c];
  for (size_t i = n; i-- > 1;) subtree[octree_.nodes[i].parent] += subtree[i];  // breadth-first: children last
  const double threshold = config_.c_ray * std::max(samples_counted, 1.0);
  bins_ = 0;
  bin_node_.clear();
  for (size_t i = 0; i < n; ++i) {
    const formats::SvoNode& node = octree_.nodes[i];
    const bool marked = node.level >= l_min_ && subtree[i] > 0 && (node.level == l_min_ || double(subtree[i]) >= threshold);
    if (marked) {
      node_bin_[i] = bins_++;
      bin_node_.push_back(uint32_t(i));
    } else {
      node_bin_[i] = i == 0 || node.parent == formats::kSvoNoParent ? kNoBin : node_bin_[node.parent];
    }
  }
  // Vertices per (bin, class): a record only where vertices were.
  record_index_.assign(size_t(bins_) * kGuideNormalClasses, kNoRecord);
  for (size_t i = 0; i < n; ++i) {
    if (node_bin_[i] == kNoBin) continue;
    for (uint32_t c = 0; c < kGuideNormalClasses; ++c)
      if (per_class[i * kGuideNormalClasses + c] > 0) record_index_[size_t(node_bin_[i]) * kGuideNormalClasses + c] = 0;
  }
}

void SvoGuidingFields::build_records(uint64_t seed) {
  // Texels per (bin, class), in texel order: the capture origin candidates.
  const size_t keys = size_t(bins_) * kGuideNormalClasses;
  std::vector<uint32_t> first(keys + 1, 0);
  std::vector<uint32_t> key_of(gbuffer_.texels.size(), kNoRecord);
  for (size_t i = 0; i < gbuffer_.texels.size(); ++i) {
    const uint32_t node = texel_node_[i];
    if (node == kNoNode || node_bin_[node] == kNoBin) continue;
    const size_t key = size_t(node_bin_[node]) * kGuideNormalClasses + guide_normal_class(gbuffer_.texels[i].shading_normal);
    if (record_index_[key] == kNoRecord) continue;  // no vertices of that class there
    key_of[i] = uint32_t(key);
    ++first[key + 1];
  }
  for (size_t k = 0; k < keys; ++k) first[k + 1] += first[k];
  std::vector<uint32_t> candidates(first[keys]);
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  for (size_t i = 0; i < gbuffer_.texels.size(); ++i)
    if (key_of[i] != kNoRecord) candidates[fill[key_of[i]]++] = uint32_t(i);

  record_bin_.clear(), record_class_.clear(), record_origin_.clear(), record_origin_normal_.clear();
  for (size_t key = 0; key < keys; ++key) {
    const uint32_t count = first[key + 1] - first[key];
    if (count == 0) {
      record_index_[key] = kNoRecord;
      continue;
    }
    const uint64_t h = splitmix64(seed ^ splitmix64((uint64_t(rebuilds_) << 40) ^ key ^ 0x5C0u));
    const LiveTexel& t = gbuffer_.texels[candidates[first[key] + uint32_t(h % count)]];
    record_index_[key] = uint32_t(record_bin_.size());
    record_bin_.push_back(uint32_t(key / kGuideNormalClasses));
    record_class_.push_back(uint32_t(key % kGuideNormalClasses));
    record_origin_.push_back(t.position);
    record_origin_normal_.push_back(t.geometric_normal);
  }
  const size_t records = record_bin_.size();
  record_front_.assign(2 * records, 0.0f);
  cdf_.assign(records * (kGuideBins + 1), 0.0f);
  field_.assign(records * kGuideBins, 0.0f);
  // Records on all cores: each traces its own field from its own random stream into its own rows
  // (the ray casts are thread-safe: Embree, or the BVH4 with a stack per thread), so the fields do
  // not depend on the thread count. One thread took 6 s per rebuild on the building at 12 texels/m.
  for_each_chunk(
      records, [&](size_t begin, size_t end) {
        for (size_t r = begin; r < end; ++r) build_field(uint32_t(r), seed);
      },
      4);
}

float SvoGuidingFields::radiance_along(Vec3 origin, Vec3 direction) const {
  const GuideRayHit hit = cast_(origin, direction);
  if (!hit.found) return luminance(scene_sky_radiance(scene_, direction));
  const Vec3 p = origin + direction * hit.distance;
  const uint32_t level = svo_guide_cone_level(kBinSolidAngle, hit.distance, octree_.size, octree_.depth);
  float radiance = 0;
  const uint32_t node = formats::svo_find_node(octree_, {p.x, p.y, p.z}, level);
  if (node != formats::kSvoNoParent) {
    const int side = dot(node_normals_[node], direction) < 0 ? 0 : 1;  // the side facing the ray
    radiance = luminance(to_vec3(formats::svo_node_exitance(octree_, node, side))) * kInvPi;
  }
  // Emitters may have no texels (then the octree never saw them): their own emission counts too.
  const Vec3 ng = triangle_geometric_normal(scene_, hit.triangle);
  if (!config_.emitted) return std::isfinite(radiance) ? std::max(radiance, 0.0f) : 0.0f;
  if (dot(direction, ng) < 0 || material_double_sided(scene_material(scene_, scene_triangle_material(scene_, hit.triangle)))) {
    float b1, b2;
    barycentrics_on_triangle(scene_, hit.triangle, p, b1, b2);
    radiance = std::max(radiance, luminance(scene_emission(scene_, hit.triangle, b1, b2)));
  }
  return std::isfinite(radiance) ? std::max(radiance, 0.0f) : 0.0f;
}

void SvoGuidingFields::build_field(uint32_t record, uint64_t seed) {
  const uint32_t normal_class = record_class_[record];
  const Vec3 ng = record_origin_normal_[record];
  const Vec3 origin = offset_ray_origin(record_origin_[record], ng, scene_.extent);
  float* field = &field_[size_t(record) * kGuideBins];
  const uint64_t stream = splitmix64(seed ^ splitmix64((uint64_t(rebuilds_) << 32) ^ record ^ 0xF1E1Dull));
  const uint32_t k = std::max(1u, uint32_t(std::sqrt(double(std::max(1u, config_.rays_per_bin)) + 1e-9)));
  for (uint32_t b = 0; b < kGuideBins; ++b) {
    double sum = 0;
    for (uint32_t s = 0; s < k * k; ++s) {
      const uint64_t h = splitmix64(stream + uint64_t(b) * k * k + s);
      const float fx = (float(s % k) + unit_float(h)) / float(k), fy = (float(s / k) + unit_float(splitmix64(h))) / float(k);
      const Vec3 d = guide_from_class_local(normal_class, guide_bin_point(b, std::min(fx, 0.99999994f), std::min(fy, 0.99999994f)));
      // Directions under the capture texel's surface carry nothing it can receive.
      if (dot(d, ng) > 0) sum += radiance_along(origin, d);
    }
    field[b] = float(sum / double(k * k));
  }
  // [1 2 1] x [1 2 1] / 16 on the square, weights renormalised at its edges.
  constexpr int n = int(kGuideBinsPerSide);
  double blurred[kGuideBins];
  double total = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double sum = 0, weights = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int sx = x + dx, sy = y + dy;
          if (sx < 0 || sy < 0 || sx >= n || sy >= n) continue;
          const double w = (dx == 0 ? 2.0 : 1.0) * (dy == 0 ? 2.0 : 1.0);
          sum += w * field[sy * n + sx];
          weights += w;
        }
      blurred[y * n + x] = sum / weights;
      total += blurred[y * n + x];
    }
  const bool usable = total > 0 && std::isfinite(total);
  record_front_[2 * size_t(record)] = usable ? config_.mix : 0.0f;
  uint32_t bits = normal_class;
  std::memcpy(&record_front_[2 * size_t(record) + 1], &bits, sizeof bits);
  float* cdf = &cdf_[size_t(record) * (kGuideBins + 1)];
  double run = 0;
  cdf[0] = 0;
  for (uint32_t b = 0; b < kGuideBins; ++b) {
    const double share = usable ? blurred[b] / total : 1.0 / kGuideBins;
    run += (1.0 - kUniformFloor) * share + kUniformFloor / kGuideBins;
    cdf[b + 1] = float(std::min(run, 1.0));
  }
  cdf[kGuideBins] = 1.0f;
}

size_t SvoGuidingFields::bytes_per_record() {
  return sizeof(float) * (2 + (kGuideBins + 1) + kGuideBins) + sizeof(uint32_t) * (2 + kGuideNormalClasses) +
         2 * sizeof(Vec3);
}

size_t SvoGuidingFields::memory_bytes() const {
  // Per node: the octree copy, links, bin, six counters, decoded normal, and the exitance cache's
  // decoded normal and pending/published sides (svo_exitance.h).
  const size_t per_node = sizeof(formats::SvoNode) + 2 * sizeof(uint32_t) + sizeof(uint32_t) +
                          kGuideNormalClasses * sizeof(uint32_t) + 2 * sizeof(Vec3) + 2 * 32 + 2 * 24;
  return octree_.nodes.size() * per_node + bytes_per_record() * record_bin_.size() +
         texel_node_.size() * sizeof(uint32_t) + bin_node_.size() * sizeof(uint32_t);
}

}  // namespace exitance
