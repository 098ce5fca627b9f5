// Helpers for the corrupt-file tests: patch little-endian fields of an encoded file and recompute
// its two CRC-32s (the last 8 header bytes: payload CRC, then header CRC), so a test can hand the
// reader a structurally wrong file whose checksums are right.
#pragma once
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "exitance/formats/crc32.h"
#include "exitance/formats/format_error.h"

namespace exitance::test {

inline uint32_t get_u32(const std::vector<uint8_t>& bytes, size_t offset) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(bytes.at(offset + size_t(i))) << (8 * i);
  return v;
}
inline uint64_t get_u64(const std::vector<uint8_t>& bytes, size_t offset) {
  return uint64_t(get_u32(bytes, offset)) | (uint64_t(get_u32(bytes, offset + 4)) << 32);
}
inline void put_u32(std::vector<uint8_t>& bytes, size_t offset, uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes.at(offset + size_t(i)) = uint8_t(v >> (8 * i));
}
inline void put_u16(std::vector<uint8_t>& bytes, size_t offset, uint16_t v) {
  for (int i = 0; i < 2; ++i) bytes.at(offset + size_t(i)) = uint8_t(v >> (8 * i));
}
inline void put_f32(std::vector<uint8_t>& bytes, size_t offset, float v) { put_u32(bytes, offset, std::bit_cast<uint32_t>(v)); }

inline void refresh_checksums(std::vector<uint8_t>& bytes, size_t header_size) {
  put_u32(bytes, header_size - 8, formats::crc32(bytes.data() + header_size, bytes.size() - header_size));
  put_u32(bytes, header_size - 4, formats::crc32(bytes.data(), header_size - 4));
}

// Runs `read` and expects a FormatError whose message contains `expected_part`.
template <typename Read>
void expect_format_error(Read&& read, const std::string& expected_part) {
  try {
    read();
    ADD_FAILURE() << "no FormatError; expected one mentioning \"" << expected_part << "\"";
  } catch (const formats::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(expected_part), std::string::npos)
        << "message \"" << e.what() << "\" does not mention \"" << expected_part << "\"";
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "message is not one line: " << e.what();
  }
}

}  // namespace exitance::test
