#include "exitance/formats/svo_file.h"

#include <bit>
#include <cmath>
#include <limits>

#include "binary_io.h"
#include "framed_file.h"

namespace exitance::formats {
namespace {

constexpr framing::FileKind kSvoKind{kSvoMagic, kSvoFormatVersion, kSvoHeaderSize, kSvoFormatVersion};
constexpr uint16_t kKnownSvoFlags = kSvoLeaf | kSvoFrontLit | kSvoBackLit | kSvoFrontFilled | kSvoBackFilled;

constexpr float kLargestHalf = 65504.0f;

bool half_is_finite(uint16_t h) { return (h & 0x7C00u) != 0x7C00u; }

std::string node_prefix(const std::string& name, size_t index) { return name + ": node " + std::to_string(index) + ": "; }

void validate_scalars(const SparseVoxelOctree& svo, const std::string& name) {
  for (float v : svo.origin)
    if (!std::isfinite(v)) throw FormatError(name + ": header: origin is not finite");
  if (!(std::isfinite(svo.size) && svo.size >= 0))
    throw FormatError(name + ": header: size " + std::to_string(svo.size) + " is not a finite non-negative number");
  if (svo.depth > kSvoMaxDepth)
    throw FormatError(name + ": header: depth " + std::to_string(svo.depth) + " exceeds the maximum " +
                      std::to_string(kSvoMaxDepth));
  // The largest finite half times the scale must stay a finite float, so lookups never return Inf.
  if (!(std::isfinite(svo.exitance_scale) && svo.exitance_scale >= 0 &&
        svo.exitance_scale <= std::numeric_limits<float>::max() / kLargestHalf))
    throw FormatError(name + ": header: exitance_scale " + std::to_string(svo.exitance_scale) +
                      " is not a finite non-negative number below float max / 65504");
  if (svo.nodes.size() > kMaxSvoNodeCount)
    throw FormatError(name + ": header: " + std::to_string(svo.nodes.size()) + " nodes exceed the limit of " +
                      std::to_string(kMaxSvoNodeCount));
}

void validate_level_table(const SparseVoxelOctree& svo, const std::string& name) {
  const std::vector<uint32_t>& begin = svo.level_begin;
  if (begin.size() != size_t(svo.depth) + 2)
    throw FormatError(name + ": level table has " + std::to_string(begin.size()) + " entries, depth " +
                      std::to_string(svo.depth) + " needs " + std::to_string(svo.depth + 2));
  if (begin.front() != 0) throw FormatError(name + ": level 0 does not start at node 0");
  for (size_t l = 0; l + 1 < begin.size(); ++l)
    if (begin[l + 1] < begin[l])
      throw FormatError(name + ": level " + std::to_string(l + 1) + " starts at node " + std::to_string(begin[l + 1]) +
                        ", before level " + std::to_string(l) + " (" + std::to_string(begin[l]) + ")");
  if (begin.back() != svo.nodes.size())
    throw FormatError(name + ": level table ends at node " + std::to_string(begin.back()) + " but there are " +
                      std::to_string(svo.nodes.size()) + " nodes");
  if (!svo.nodes.empty()) {
    if (begin[1] != 1) throw FormatError(name + ": level 0 holds " + std::to_string(begin[1]) + " nodes, not the single root");
    if (!(svo.size > 0)) throw FormatError(name + ": header: size is 0 but the octree has nodes");
  }
}

void validate_node_fields(const SvoNode& n, size_t index, uint32_t level, uint32_t depth, const std::string& name) {
  if (n.level != level)
    throw FormatError(node_prefix(name, index) + "level field " + std::to_string(n.level) + " but it lies in level " +
                      std::to_string(level));
  if (n.flags & ~kKnownSvoFlags)
    throw FormatError(node_prefix(name, index) + "undefined flag bits " + std::to_string(n.flags & ~kKnownSvoFlags));
  const bool is_leaf_level = level == depth;
  if (bool(n.flags & kSvoLeaf) != is_leaf_level)
    throw FormatError(node_prefix(name, index) + (is_leaf_level ? "leaf level but the leaf flag is not set"
                                                                 : "leaf flag set above the leaf level " + std::to_string(depth)));
  if (is_leaf_level && n.child_mask != 0) throw FormatError(node_prefix(name, index) + "leaf with children");
  if (n.child_mask == 0 && n.first_child != 0)
    throw FormatError(node_prefix(name, index) + "first_child " + std::to_string(n.first_child) + " without children");
  for (int i = 0; i < 6; ++i)
    if (!half_is_finite(n.exitance[i]))
      throw FormatError(node_prefix(name, index) + (i < 3 ? "front" : "back") + " exitance is not finite");
}

// Children of level l are level l+1 exactly, contiguous, in parent order: walking the parents in
// order, each one's first_child must be where the previous parent's children ended.
void validate_tree_links(const SparseVoxelOctree& svo, const std::string& name) {
  if (svo.nodes.empty()) return;
  const std::vector<uint32_t>& begin = svo.level_begin;
  if (svo.nodes[0].parent != kSvoNoParent)
    throw FormatError(node_prefix(name, 0) + "the root's parent is " + std::to_string(svo.nodes[0].parent) + ", not none");
  for (uint32_t level = 0; level <= svo.depth; ++level) {
    const bool has_next_level = level < svo.depth;
    uint64_t next_child = has_next_level ? begin[level + 1] : 0;
    const uint64_t next_level_end = has_next_level ? begin[level + 2] : 0;
    for (uint32_t i = begin[level]; i < begin[level + 1]; ++i) {
      const SvoNode& n = svo.nodes[i];
      validate_node_fields(n, i, level, svo.depth, name);
      if (n.child_mask == 0) continue;
      const uint32_t child_level = level + 1;
      if (n.first_child < begin[child_level] || n.first_child >= next_level_end)
        throw FormatError(node_prefix(name, i) + "child index " + std::to_string(n.first_child) + " outside level " +
                          std::to_string(child_level));
      if (n.first_child != next_child)
        throw FormatError(node_prefix(name, i) + "children start at node " + std::to_string(n.first_child) +
                          ", breadth-first order needs " + std::to_string(next_child));
      const uint64_t end = uint64_t(n.first_child) + uint64_t(std::popcount(unsigned(n.child_mask)));
      if (end > next_level_end)
        throw FormatError(node_prefix(name, i) + "child index " + std::to_string(end - 1) + " outside level " +
                          std::to_string(child_level));
      for (uint64_t c = n.first_child; c < end; ++c)
        if (svo.nodes[size_t(c)].parent != i)
          throw FormatError(node_prefix(name, size_t(c)) + "parent " + std::to_string(svo.nodes[size_t(c)].parent) +
                            ", but node " + std::to_string(i) + " lists it as a child");
      next_child = end;
    }
    if (has_next_level && next_child != next_level_end)
      throw FormatError(name + ": level " + std::to_string(level + 1) + ": nodes " + std::to_string(next_child) + ".." +
                        std::to_string(next_level_end - 1) + " are no node's children");
  }
}

}  // namespace

void validate_octree(const SparseVoxelOctree& svo, const std::string& name) {
  validate_scalars(svo, name);
  validate_level_table(svo, name);
  validate_tree_links(svo, name);
}

std::vector<uint8_t> encode_svo(const SparseVoxelOctree& svo) {
  validate_octree(svo, "svo.bin (writing)");
  std::vector<uint8_t> header;
  binary_io::LittleEndianWriter h(header);
  for (float v : svo.origin) h.f32(v);
  h.f32(svo.size);
  h.u32(svo.depth);
  h.f32(svo.exitance_scale);
  h.u32(uint32_t(svo.nodes.size()));
  h.u32(uint32_t(svo.level_begin.size()));
  h.u32(kSvoNodeRecordSize);
  h.u32(0);  // reserved: keeps the u64 payload size 8-byte aligned

  std::vector<uint8_t> payload;
  payload.reserve(svo.level_begin.size() * 4 + svo.nodes.size() * kSvoNodeRecordSize);
  binary_io::LittleEndianWriter p(payload);
  for (uint32_t v : svo.level_begin) p.u32(v);
  for (const SvoNode& n : svo.nodes) {
    p.u32(n.first_child);
    p.u32(n.parent);
    p.u8(n.child_mask);
    p.u8(n.level);
    p.u16(n.flags);
    p.u32(n.normal_oct);
    for (uint16_t e : n.exitance) p.u16(e);
  }
  return framing::build_frame(kSvoKind, header, payload);
}

void write_svo_file(const std::string& path, const SparseVoxelOctree& svo) {
  binary_io::write_whole_file(path, encode_svo(svo));
}

SparseVoxelOctree read_svo(const uint8_t* data, size_t size, const std::string& name) {
  const framing::FramedView frame = framing::open_frame(data, size, kSvoKind, name);
  binary_io::LittleEndianReader h(frame.header, kSvoHeaderSize, name);
  h.skip(16);
  SparseVoxelOctree svo;
  for (float& v : svo.origin) v = h.f32();
  svo.size = h.f32();
  svo.depth = h.u32();
  svo.exitance_scale = h.f32();
  const uint32_t node_count = h.u32();
  const uint32_t level_count = h.u32();
  const uint32_t record_size = h.u32();
  const uint32_t reserved = h.u32();

  if (svo.depth > kSvoMaxDepth)
    throw FormatError(name + ": header: depth " + std::to_string(svo.depth) + " exceeds the maximum " +
                      std::to_string(kSvoMaxDepth));
  if (level_count != svo.depth + 2)
    throw FormatError(name + ": header: level count " + std::to_string(level_count) + ", depth " +
                      std::to_string(svo.depth) + " needs " + std::to_string(svo.depth + 2));
  if (record_size != kSvoNodeRecordSize)
    throw FormatError(name + ": header: node record size " + std::to_string(record_size) + " is not " +
                      std::to_string(kSvoNodeRecordSize));
  if (reserved != 0) throw FormatError(name + ": header: reserved field is " + std::to_string(reserved) + ", not 0");
  if (node_count > kMaxSvoNodeCount)
    throw FormatError(name + ": header: " + std::to_string(node_count) + " nodes exceed the limit of " +
                      std::to_string(kMaxSvoNodeCount));
  const uint64_t expected_payload = uint64_t(level_count) * 4 + uint64_t(node_count) * kSvoNodeRecordSize;
  if (frame.payload_size != expected_payload)
    throw FormatError(name + ": payload: " + std::to_string(frame.payload_size) + " bytes, " +
                      std::to_string(node_count) + " nodes and " + std::to_string(level_count) + " levels need " +
                      std::to_string(expected_payload));

  // The payload size now bounds both counts, so these allocations are backed by real bytes.
  binary_io::LittleEndianReader p(frame.payload, size_t(frame.payload_size), name);
  svo.level_begin.resize(level_count);
  for (uint32_t& v : svo.level_begin) v = p.u32();
  svo.nodes.resize(node_count);
  for (SvoNode& n : svo.nodes) {
    n.first_child = p.u32();
    n.parent = p.u32();
    n.child_mask = p.u8();
    n.level = p.u8();
    n.flags = p.u16();
    n.normal_oct = p.u32();
    for (uint16_t& e : n.exitance) e = p.u16();
  }
  validate_octree(svo, name);
  return svo;
}

SparseVoxelOctree read_svo_file(const std::string& path) {
  const std::vector<uint8_t> bytes = binary_io::read_whole_file(path);
  return read_svo(bytes.data(), bytes.size(), path);
}

}  // namespace exitance::formats
