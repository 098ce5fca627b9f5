// svo.bin: exact round trips, the documented byte layout, refusal of every truncation and
// single-byte corruption, other versions, and structurally wrong octrees with right checksums
// (the checks that keep svo_find_node inside the node array).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "byte_patching.h"
#include "exitance/formats/svo_file.h"
#include "test_bundle.h"

namespace exitance::formats {
namespace {

using test::expect_format_error;
using test::put_f32;
using test::put_u16;
using test::put_u32;
using test::refresh_checksums;

constexpr size_t kHeader = kSvoHeaderSize;
constexpr size_t kLevelTable = kHeader;                  // depth 2: 4 u32 entries
constexpr size_t kNodes = kHeader + 4 * 4;
size_t node_offset(size_t node) { return kNodes + node * kSvoNodeRecordSize; }
// Field offsets inside a 28-byte node record.
constexpr size_t kFirstChild = 0, kParent = 4, kChildMask = 8, kLevel = 9, kFlags = 10, kExitance = 16;

SparseVoxelOctree read(const std::vector<uint8_t>& bytes) { return read_svo(bytes.data(), bytes.size(), "svo.bin"); }

void expect_bitwise_equal(const SparseVoxelOctree& a, const SparseVoxelOctree& b) {
  EXPECT_EQ(std::memcmp(a.origin.data(), b.origin.data(), sizeof(a.origin)), 0);
  EXPECT_EQ(std::bit_cast<uint32_t>(a.size), std::bit_cast<uint32_t>(b.size));
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(std::bit_cast<uint32_t>(a.exitance_scale), std::bit_cast<uint32_t>(b.exitance_scale));
  EXPECT_EQ(a.level_begin, b.level_begin);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) EXPECT_EQ(std::memcmp(&a.nodes[i], &b.nodes[i], sizeof(SvoNode)), 0) << "node " << i;
}

TEST(SvoFile, RoundTripIsBitwiseExact) {
  SparseVoxelOctree svo = test::make_test_octree();
  svo.origin = {-1e5f, 0.1f, std::numeric_limits<float>::denorm_min()};
  svo.nodes[3].exitance[0] = 0x0001;  // smallest subnormal half
  svo.nodes[3].exitance[4] = 0x7BFF;  // largest finite half
  svo.nodes[4].normal_oct = 0xFFFF8001u;
  svo.nodes[5].flags |= kSvoBackFilled;
  const std::vector<uint8_t> bytes = encode_svo(svo);
  const SparseVoxelOctree back = read(bytes);
  expect_bitwise_equal(svo, back);
  EXPECT_EQ(encode_svo(back), bytes);

  const std::string path = test::fresh_directory("svo-round-trip") + "/svo.bin";
  write_svo_file(path, svo);
  expect_bitwise_equal(svo, read_svo_file(path));
}

TEST(SvoFile, EmptyOctreeRoundTrips) {
  SparseVoxelOctree empty;
  empty.level_begin = {0, 0};
  const SparseVoxelOctree back = read(encode_svo(empty));
  EXPECT_TRUE(back.nodes.empty());
  EXPECT_EQ(svo_find_node(back, {0, 0, 0}, 5), kSvoNoParent);
}

TEST(SvoFile, HeaderAndNodesHaveTheDocumentedLayout) {
  const SparseVoxelOctree svo = test::make_test_octree();
  const std::vector<uint8_t> bytes = encode_svo(svo);
  ASSERT_EQ(bytes.size(), kHeader + 4 * 4 + 6 * 28);
  EXPECT_EQ(std::memcmp(bytes.data(), "EXSVO\0\0\0", 8), 0);
  EXPECT_EQ(test::get_u32(bytes, 8), 1u);
  EXPECT_EQ(test::get_u32(bytes, 12), 72u);
  EXPECT_EQ(std::bit_cast<float>(test::get_u32(bytes, 28)), 8.0f);  // size
  EXPECT_EQ(test::get_u32(bytes, 32), 2u);                           // depth
  EXPECT_EQ(std::bit_cast<float>(test::get_u32(bytes, 36)), test::kSvoExitanceScale);
  EXPECT_EQ(test::get_u32(bytes, 40), 6u);   // node count
  EXPECT_EQ(test::get_u32(bytes, 44), 4u);   // level count
  EXPECT_EQ(test::get_u32(bytes, 48), 28u);  // node record size
  EXPECT_EQ(test::get_u32(bytes, 52), 0u);   // reserved
  EXPECT_EQ(test::get_u64(bytes, 56), 4u * 4u + 6u * 28u);
  EXPECT_EQ(test::get_u32(bytes, 64), crc32(bytes.data() + kHeader, bytes.size() - kHeader));
  EXPECT_EQ(test::get_u32(bytes, 68), crc32(bytes.data(), 68));
  EXPECT_EQ(test::get_u32(bytes, kLevelTable + 8), 3u);  // level 2 begins at node 3
  EXPECT_EQ(test::get_u32(bytes, node_offset(1) + kFirstChild), 3u);
  EXPECT_EQ(test::get_u32(bytes, node_offset(1) + kParent), 0u);
  EXPECT_EQ(bytes[node_offset(0) + kChildMask], 0x81);
  EXPECT_EQ(bytes[node_offset(4) + kLevel], 2);
  EXPECT_EQ(bytes[node_offset(4) + kFlags], kSvoLeaf | kSvoFrontLit);
  EXPECT_EQ(test::get_u32(bytes, node_offset(5) + 12), svo.nodes[5].normal_oct);
  EXPECT_EQ(bytes[node_offset(2) + kExitance + 6], svo.nodes[2].exitance[3] & 0xFF);  // back R, low byte
}

TEST(SvoFile, EveryTruncationIsRefused) {
  const std::vector<uint8_t> bytes = encode_svo(test::make_test_octree());
  for (size_t length = 0; length < bytes.size(); ++length)
    EXPECT_THROW(read_svo(bytes.data(), length, "svo.bin"), FormatError) << "length " << length;
}

TEST(SvoFile, EverySingleByteCorruptionIsRefused) {
  const std::vector<uint8_t> original = encode_svo(test::make_test_octree());
  for (size_t position = 0; position < original.size(); ++position)
    for (uint8_t flip : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
      std::vector<uint8_t> bytes = original;
      bytes[position] ^= flip;
      EXPECT_THROW(read(bytes), FormatError) << "byte " << position << " xor " << int(flip);
    }
}

TEST(SvoFile, OtherVersionsAreRefusedByName) {
  std::vector<uint8_t> bytes = encode_svo(test::make_test_octree());
  put_u32(bytes, 8, 3);
  try {
    read(bytes);
    FAIL() << "version 3 accepted";
  } catch (const FormatError& e) {
    EXPECT_STREQ(e.what(), "svo.bin: format version 3 is newer than this loader (1)");
  }
  put_u32(bytes, 8, 0);
  expect_format_error([&] { read(bytes); }, "svo.bin: format version 0 is older than this loader supports (1)");
}

TEST(SvoFile, BadChildIndexIsRefusedEvenWithRightChecksums) {
  std::vector<uint8_t> bytes = encode_svo(test::make_test_octree());
  put_u32(bytes, node_offset(1) + kFirstChild, 99999);
  refresh_checksums(bytes, kHeader);
  expect_format_error([&] { read(bytes); }, "svo.bin: node 1: child index 99999 outside level 2");
}

struct StructuralCase {
  const char* name;
  void (*edit)(std::vector<uint8_t>&);
  const char* expected;
};

const StructuralCase kStructuralCases[] = {
    {"children past the level end", [](auto& b) { b[node_offset(2) + kChildMask] = 0xC0; }, "node 2: child index 6 outside level 2"},
    {"child in its own level", [](auto& b) { put_u32(b, node_offset(1) + kFirstChild, 2); }, "node 1: child index 2 outside level 2"},
    {"children out of breadth-first order",
     [](auto& b) {
       put_u32(b, node_offset(0) + kFirstChild, 2);
       b[node_offset(0) + kChildMask] = 0x01;
     },
     "node 0: children start at node 2, breadth-first order needs 1"},
    {"orphan nodes", [](auto& b) { b[node_offset(2) + kChildMask] = 0; put_u32(b, node_offset(2) + kFirstChild, 0); },
     "level 2: nodes 5..5 are no node's children"},
    {"wrong parent", [](auto& b) { put_u32(b, node_offset(4) + kParent, 2); }, "node 4: parent 2, but node 1 lists it as a child"},
    {"parent far out of range", [](auto& b) { put_u32(b, node_offset(5) + kParent, 0xFFFFFFF0u); }, "node 5: parent 4294967280"},
    {"root with a parent", [](auto& b) { put_u32(b, node_offset(0) + kParent, 0); }, "the root's parent is 0"},
    {"leaf flag missing", [](auto& b) { put_u16(b, node_offset(3) + kFlags, kSvoFrontLit); }, "node 3: leaf level but the leaf flag is not set"},
    {"leaf flag above the leaves", [](auto& b) { put_u16(b, node_offset(1) + kFlags, kSvoLeaf); }, "node 1: leaf flag set above the leaf level"},
    {"undefined flag", [](auto& b) { put_u16(b, node_offset(3) + kFlags, kSvoLeaf | 0x100); }, "node 3: undefined flag bits 256"},
    {"leaf with children", [](auto& b) { b[node_offset(4) + kChildMask] = 1; }, "node 4: leaf with children"},
    {"level field", [](auto& b) { b[node_offset(2) + kLevel] = 2; }, "node 2: level field 2 but it lies in level 1"},
    {"first_child without children", [](auto& b) { put_u32(b, node_offset(4) + kFirstChild, 1); }, "node 4: first_child 1 without children"},
    {"nan exitance", [](auto& b) { put_u16(b, node_offset(5) + kExitance + 2, 0x7E00); }, "node 5: front exitance is not finite"},
    {"inf back exitance", [](auto& b) { put_u16(b, node_offset(5) + kExitance + 8, 0xFC00); }, "node 5: back exitance is not finite"},
    {"level table not monotone", [](auto& b) { put_u32(b, kLevelTable + 4, 4); }, "level 2 starts at node 3, before level 1 (4)"},
    {"level table end", [](auto& b) { put_u32(b, kLevelTable + 12, 5); }, "level table ends at node 5 but there are 6 nodes"},
    {"two roots", [](auto& b) { put_u32(b, kLevelTable + 4, 2); }, "level 0 holds 2 nodes"},
    {"depth too deep", [](auto& b) { put_u32(b, 32, 17); }, "depth 17 exceeds the maximum 16"},
    {"level count", [](auto& b) { put_u32(b, 32, 3); }, "level count 4, depth 3 needs 5"},
    {"node count vs payload", [](auto& b) { put_u32(b, 40, 7); }, "payload: 184 bytes, 7 nodes and 4 levels need 212"},
    {"node count cap", [](auto& b) { put_u32(b, 40, 0xFFFFFFFFu); }, "nodes exceed the limit"},
    {"nan scale", [](auto& b) { put_f32(b, 36, std::nanf("")); }, "exitance_scale nan"},
    {"huge scale", [](auto& b) { put_f32(b, 36, 1e36f); }, "exitance_scale"},
    {"negative size", [](auto& b) { put_f32(b, 28, -8.0f); }, "size -8.000000 is not a finite non-negative number"},
    {"inf origin", [](auto& b) { put_f32(b, 16, INFINITY); }, "origin is not finite"},
    {"record size", [](auto& b) { put_u32(b, 48, 32); }, "node record size 32"},
    {"reserved", [](auto& b) { put_u32(b, 52, 1); }, "reserved field is 1"},
};

TEST(SvoFile, StructurallyWrongOctreesWithRightChecksumsAreRefused) {
  const std::vector<uint8_t> original = encode_svo(test::make_test_octree());
  for (const StructuralCase& c : kStructuralCases) {
    SCOPED_TRACE(c.name);
    std::vector<uint8_t> bytes = original;
    c.edit(bytes);
    refresh_checksums(bytes, kHeader);
    expect_format_error([&] { read(bytes); }, c.expected);
  }
}

TEST(SvoFile, WriterRefusesAnInvalidOctree) {
  SparseVoxelOctree svo = test::make_test_octree();
  svo.nodes[1].first_child = 4;
  expect_format_error([&] { encode_svo(svo); }, "svo.bin (writing): node 1: children start at node 4");
  svo = test::make_test_octree();
  svo.level_begin.pop_back();
  expect_format_error([&] { encode_svo(svo); }, "level table has 3 entries, depth 2 needs 4");
}

}  // namespace
}  // namespace exitance::formats
