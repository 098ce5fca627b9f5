#include "exitance/runtime/svo_exitance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace exitance {

namespace {
Vec3 to_vec3(std::array<float, 3> a) { return {a[0], a[1], a[2]}; }
}  // namespace

SvoExitanceCache::SvoExitanceCache(const formats::SparseVoxelOctree& svo)
    : svo_(svo), normals_(svo.nodes.size()), pending_(svo.nodes.size() * 2), published_(svo.nodes.size() * 2) {
  for (size_t i = 0; i < svo.nodes.size(); ++i)
    normals_[i] = to_vec3(formats::decode_octahedral_normal(svo.nodes[i].normal_oct));
}

void SvoExitanceCache::deposit(const ExitanceSample& sample) {
  const uint32_t node =
      formats::svo_find_node(svo_, {sample.position.x, sample.position.y, sample.position.z}, svo_.depth);
  if (node == formats::kSvoNoParent || svo_.nodes[node].level != svo_.depth || !is_finite(sample.exitance) ||
      !(sample.weight > 0)) {
    ++dropped_;
    return;
  }
  const int side = dot(sample.normal, normals_[node]) >= 0 ? 0 : 1;
  SideSum& s = pending_[size_t(node) * 2 + size_t(side)];
  for (int c = 0; c < 3; ++c) s.sum[c] += double(sample.exitance[c]) * sample.weight;
  s.weight += sample.weight;
}

void SvoExitanceCache::publish(float blend) {
  if (!(blend > 0.0f && blend <= 1.0f)) throw std::invalid_argument("exitance blend must be in (0, 1]");
  for (size_t i = 0; i < pending_.size(); ++i) {
    SideSum& s = pending_[i];
    if (s.weight <= 0) continue;
    const Vec3 fresh{float(s.sum[0] / s.weight), float(s.sum[1] / s.weight), float(s.sum[2] / s.weight)};
    SideValue& v = published_[i];
    v.value = v.weight > 0 ? v.value * (1.0f - blend) + fresh * blend : fresh;
    v.weight = s.weight;
    s = SideSum{};
  }
}

void SvoExitanceCache::store_into(formats::SparseVoxelOctree& svo) const {
  if (&svo != &svo_ && svo.nodes.size() != svo_.nodes.size())
    throw std::invalid_argument("store_into: not the octree this cache was built for");
  const size_t n = svo.nodes.size();
  // The filters below rely on breadth-first order: every parent before its children.
  for (size_t i = 1; i < n; ++i)
    if (svo.nodes[i].parent >= i)
      throw std::logic_error("SVO node " + std::to_string(i) + ": parent " + std::to_string(svo.nodes[i].parent) +
                             " does not precede it");
  std::vector<SideValue> filtered(published_.begin(), published_.end());
  for (size_t i = 0; i < n; ++i)
    if (svo.nodes[i].level != svo.depth) filtered[2 * i] = filtered[2 * i + 1] = SideValue{};
  // Bottom-up: nodes are breadth-first, so walking backwards visits children before parents.
  for (size_t i = n; i-- > 1;) {
    const uint32_t parent = svo.nodes[i].parent;
    const bool flipped = dot(normals_[i], normals_[parent]) < 0;
    for (int side = 0; side < 2; ++side) {
      const SideValue& child = filtered[2 * i + size_t(side)];
      if (child.weight <= 0) continue;
      SideValue& p = filtered[2 * size_t(parent) + size_t(flipped ? 1 - side : side)];
      // Running weighted mean, so parents never need the raw sums.
      const double w = p.weight + child.weight;
      p.value = p.value * float(p.weight / w) + child.value * float(child.weight / w);
      p.weight = w;
    }
  }
  std::vector<uint16_t> flags(n * 2, 0);  // per side: 1 lit, 2 filled
  for (size_t i = 0; i < 2 * n; ++i) flags[i] = filtered[i].weight > 0 ? 1 : 0;
  // Top-down fill: parents come first in breadth-first order.
  for (size_t i = 1; i < n; ++i) {
    const uint32_t parent = svo.nodes[i].parent;
    const bool flipped = dot(normals_[i], normals_[parent]) < 0;
    for (int side = 0; side < 2; ++side) {
      if (flags[2 * i + size_t(side)] == 1) continue;
      const size_t from = 2 * size_t(parent) + size_t(flipped ? 1 - side : side);
      if (flags[from] == 0) continue;
      filtered[2 * i + size_t(side)].value = filtered[from].value;
      flags[2 * i + size_t(side)] = 2;
    }
  }
  // Halves with a power-of-two scale so the brightest value stays below 2^15 (half max 65504).
  float max_value = 0;
  for (const SideValue& v : filtered) max_value = std::max(max_value, max_component(v.value));
  float scale = 1.0f;
  if (max_value > 0) scale = std::ldexp(1.0f, int(std::ceil(std::log2(double(max_value) / 32768.0))));
  svo.exitance_scale = scale;
  for (size_t i = 0; i < n; ++i) {
    formats::SvoNode& node = svo.nodes[i];
    node.flags &= uint16_t(~(formats::kSvoFrontLit | formats::kSvoBackLit | formats::kSvoFrontFilled |
                             formats::kSvoBackFilled));
    for (int side = 0; side < 2; ++side) {
      const Vec3 v = filtered[2 * i + size_t(side)].value;
      for (int c = 0; c < 3; ++c) node.exitance[side * 3 + c] = formats::float_to_half(std::max(0.0f, v[c]) / scale);
      const uint16_t f = flags[2 * i + size_t(side)];
      if (f == 1) node.flags |= side == 0 ? formats::kSvoFrontLit : formats::kSvoBackLit;
      if (f == 2) node.flags |= side == 0 ? formats::kSvoFrontFilled : formats::kSvoBackFilled;
    }
  }
}

}  // namespace exitance
