// probes.bin: exact round trips, the documented byte layout, and refusal of every truncation,
// every single-byte corruption, other versions and structurally wrong files with right checksums.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "byte_patching.h"
#include "exitance/formats/probes_file.h"
#include "test_bundle.h"

namespace exitance::formats {
namespace {

using test::expect_format_error;
using test::put_f32;
using test::put_u32;
using test::refresh_checksums;

constexpr size_t kHeader = kProbesHeaderSize;
constexpr size_t kStateOffset = 12, kShOffset = 16;  // inside a 124-byte record

// The linear test grid plus the awkward values a round trip must keep bit for bit.
ProbeGrid awkward_grid() {
  ProbeGrid grid = test::make_linear_probe_grid();
  grid.probes[0].sh[0] = -0.0f;
  grid.probes[0].sh[1] = std::numeric_limits<float>::denorm_min();
  grid.probes[0].sh[2] = std::numeric_limits<float>::max();
  grid.probes[2].state = ProbeState::Invalid;
  grid.probes[2].sh = {};
  grid.probes[5].state = ProbeState::Skipped;
  grid.probes[5].sh = {};
  return grid;
}

size_t record_offset(size_t probe) { return kHeader + probe * kProbeRecordSize; }

ProbeGrid read(const std::vector<uint8_t>& bytes) { return read_probes(bytes.data(), bytes.size(), "probes.bin"); }

void expect_bitwise_equal(const ProbeGrid& a, const ProbeGrid& b) {
  EXPECT_EQ(std::memcmp(a.origin.data(), b.origin.data(), sizeof(a.origin)), 0);
  EXPECT_EQ(std::memcmp(a.spacing.data(), b.spacing.data(), sizeof(a.spacing)), 0);
  EXPECT_EQ(a.counts, b.counts);
  EXPECT_EQ(a.sh_order, b.sh_order);
  ASSERT_EQ(a.probes.size(), b.probes.size());
  for (size_t i = 0; i < a.probes.size(); ++i)
    EXPECT_EQ(std::memcmp(&a.probes[i], &b.probes[i], sizeof(ProbeRecord)), 0) << "probe " << i;
}

TEST(ProbesFile, RoundTripIsBitwiseExact) {
  const ProbeGrid grid = awkward_grid();
  const std::vector<uint8_t> bytes = encode_probes(grid);
  const ProbeGrid back = read(bytes);
  expect_bitwise_equal(grid, back);
  EXPECT_EQ(encode_probes(back), bytes);
  EXPECT_TRUE(std::signbit(back.probes[0].sh[0]));

  const std::string path = test::fresh_directory("probes-round-trip") + "/probes.bin";
  write_probes_file(path, grid);
  EXPECT_EQ(std::filesystem::file_size(path), bytes.size());
  expect_bitwise_equal(grid, read_probes_file(path));
}

TEST(ProbesFile, HeaderHasTheDocumentedLayout) {
  const ProbeGrid grid = awkward_grid();
  const std::vector<uint8_t> bytes = encode_probes(grid);
  ASSERT_EQ(bytes.size(), kHeader + 12 * kProbeRecordSize);
  EXPECT_EQ(std::memcmp(bytes.data(), "EXPROBES", 8), 0);
  EXPECT_EQ(test::get_u32(bytes, 8), 1u);
  EXPECT_EQ(test::get_u32(bytes, 12), 80u);
  EXPECT_EQ(std::bit_cast<float>(test::get_u32(bytes, 16)), -1.0f);  // origin.x
  EXPECT_EQ(std::bit_cast<float>(test::get_u32(bytes, 36)), 2.0f);   // spacing.z
  EXPECT_EQ(test::get_u32(bytes, 40), 3u);
  EXPECT_EQ(test::get_u32(bytes, 44), 2u);
  EXPECT_EQ(test::get_u32(bytes, 48), 2u);
  EXPECT_EQ(test::get_u32(bytes, 52), 2u);   // sh_order
  EXPECT_EQ(test::get_u32(bytes, 56), 12u);  // probe count
  EXPECT_EQ(test::get_u32(bytes, 60), 124u);
  EXPECT_EQ(test::get_u64(bytes, 64), 12u * 124u);
  EXPECT_EQ(test::get_u32(bytes, 72), crc32(bytes.data() + kHeader, bytes.size() - kHeader));
  EXPECT_EQ(test::get_u32(bytes, 76), crc32(bytes.data(), 76));
  // Record 2: position, state, coefficients.
  EXPECT_EQ(std::bit_cast<float>(test::get_u32(bytes, record_offset(2))), grid.probes[2].position[0]);
  EXPECT_EQ(test::get_u32(bytes, record_offset(2) + kStateOffset), uint32_t(ProbeState::Invalid));
  EXPECT_EQ(std::bit_cast<float>(test::get_u32(bytes, record_offset(1) + kShOffset + 4 * 26)), grid.probes[1].sh[26]);
}

TEST(ProbesFile, EveryTruncationIsRefused) {
  const std::vector<uint8_t> bytes = encode_probes(awkward_grid());
  for (size_t length = 0; length < bytes.size(); ++length)
    EXPECT_THROW(read_probes(bytes.data(), length, "probes.bin"), FormatError) << "length " << length;
}

TEST(ProbesFile, TrailingBytesAreRefused) {
  std::vector<uint8_t> bytes = encode_probes(awkward_grid());
  bytes.push_back(0);
  expect_format_error([&] { read(bytes); }, "unexpected bytes after the payload");
}

TEST(ProbesFile, EverySingleByteCorruptionIsRefused) {
  const std::vector<uint8_t> original = encode_probes(awkward_grid());
  for (size_t position = 0; position < original.size(); ++position)
    for (uint8_t flip : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
      std::vector<uint8_t> bytes = original;
      bytes[position] ^= flip;
      EXPECT_THROW(read(bytes), FormatError) << "byte " << position << " xor " << int(flip);
    }
}

TEST(ProbesFile, OtherVersionsAreRefusedByName) {
  std::vector<uint8_t> bytes = encode_probes(awkward_grid());
  put_u32(bytes, 8, 3);
  refresh_checksums(bytes, kHeader);
  try {
    read(bytes);
    FAIL() << "version 3 accepted";
  } catch (const FormatError& e) {
    EXPECT_STREQ(e.what(), "probes.bin: format version 3 is newer than this loader (1)");
  }
  put_u32(bytes, 8, 0);
  refresh_checksums(bytes, kHeader);
  expect_format_error([&] { read(bytes); }, "probes.bin: format version 0 is older than this loader supports (1)");
}

TEST(ProbesFile, WrongMagicIsRefused) {
  std::vector<uint8_t> bytes = encode_probes(awkward_grid());
  bytes[0] = 'X';
  expect_format_error([&] { read(bytes); }, "wrong magic");
}

// Each case edits a valid file, recomputes the checksums, and names what the message must say.
struct StructuralCase {
  const char* name;
  void (*edit)(std::vector<uint8_t>&);
  const char* expected;
};

const StructuralCase kStructuralCases[] = {
    {"nan position", [](auto& b) { put_f32(b, record_offset(3) + 4, std::nanf("")); }, "probe 3: position is not finite"},
    {"inf coefficient", [](auto& b) { put_f32(b, record_offset(7) + kShOffset + 4 * 5, INFINITY); },
     "probe 7: SH coefficient 1 channel 2 is not finite"},
    {"unknown state", [](auto& b) { put_u32(b, record_offset(4) + kStateOffset, 7); }, "probe 4: state 7 is not a known ProbeState"},
    {"nan origin", [](auto& b) { put_f32(b, 20, std::nanf("")); }, "origin is not finite"},
    {"zero spacing", [](auto& b) { put_f32(b, 32, 0.0f); }, "spacing 0.000000 on axis 1"},
    {"zero count", [](auto& b) { put_u32(b, 44, 0); }, "include a zero"},
    {"huge counts", [](auto& b) { for (size_t o : {40, 44, 48}) put_u32(b, o, 0x10000); }, "exceed the limit"},
    {"counts overflow 64 bits",
     [](auto& b) { for (size_t o : {40, 44, 48}) put_u32(b, o, 0xFFFFFFFFu); }, "exceed the limit"},
    {"counts disagree with payload",
     [](auto& b) {
       put_u32(b, 40, 4);
       put_u32(b, 56, 16);
     },
     "payload: 1488 bytes, 16 probes need 1984"},
    {"probe count field", [](auto& b) { put_u32(b, 56, 11); }, "probe count 11 is not 3 x 2 x 2"},
    {"record size", [](auto& b) { put_u32(b, 60, 128); }, "probe record size 128"},
    {"sh order", [](auto& b) { put_u32(b, 52, 3); }, "sh_order 3 is not supported"},
    {"header size", [](auto& b) { put_u32(b, 12, 96); }, "header: size 96 is not 80"},
    {"payload size", [](auto& b) { test::put_u32(b, 64, 124); }, "unexpected bytes after the payload"},
};

TEST(ProbesFile, StructurallyWrongFilesWithRightChecksumsAreRefused) {
  const std::vector<uint8_t> original = encode_probes(awkward_grid());
  for (const StructuralCase& c : kStructuralCases) {
    SCOPED_TRACE(c.name);
    std::vector<uint8_t> bytes = original;
    c.edit(bytes);
    refresh_checksums(bytes, kHeader);
    expect_format_error([&] { read(bytes); }, c.expected);
  }
}

TEST(ProbesFile, WriterRefusesAnInvalidGrid) {
  ProbeGrid grid = awkward_grid();
  grid.probes.pop_back();
  expect_format_error([&] { encode_probes(grid); }, "11 probes for a grid of 3 x 2 x 2");
  grid = awkward_grid();
  grid.probes[1].sh[4] = std::nanf("");
  expect_format_error([&] { encode_probes(grid); }, "probe 1: SH coefficient 1 channel 1 is not finite");
}

TEST(ProbesFile, MissingFileIsAnAccessError) {
  EXPECT_THROW(read_probes_file(test::fresh_directory("probes-missing") + "/nope.bin"), FileAccessError);
  EXPECT_THROW(read_probes_file(test::fresh_directory("probes-dir")), FileAccessError);
}

}  // namespace
}  // namespace exitance::formats
