// CRC-32 against the IEEE check value and its incremental form.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "exitance/formats/crc32.h"

namespace exitance::formats {
namespace {

TEST(Crc32, MatchesTheIeeeCheckValue) {
  const std::string text = "123456789";  // the catalogue check input; CRC-32/ISO-HDLC = 0xCBF43926
  EXPECT_EQ(crc32(reinterpret_cast<const uint8_t*>(text.data()), text.size()), 0xCBF43926u);
  EXPECT_EQ(crc32(nullptr, 0), 0u);
}

TEST(Crc32, ContinuesARunningValue) {
  const std::string text = "The quick brown fox jumps over the lazy dog";
  const auto* data = reinterpret_cast<const uint8_t*>(text.data());
  EXPECT_EQ(crc32(data, text.size()), 0x414FA339u);  // zlib.crc32 of the same bytes
  EXPECT_EQ(crc32(data + 10, text.size() - 10, crc32(data, 10)), crc32(data, text.size()));
}

// The byte-at-a-time definition, to check the eight-bytes-at-a-time implementation against.
uint32_t bitwise_crc32(const uint8_t* data, size_t size) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < size; ++i) {
    c ^= data[i];
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

TEST(Crc32, EqualsTheBitwiseDefinitionAtEveryLengthAndAlignment) {
  std::vector<uint8_t> bytes(300);
  uint32_t state = 12345;
  for (uint8_t& b : bytes) b = uint8_t((state = state * 1664525u + 1013904223u) >> 24);
  for (size_t start = 0; start < 9; ++start)
    for (size_t size = 0; start + size <= bytes.size(); size += 1 + size / 8) {
      ASSERT_EQ(crc32(bytes.data() + start, size), bitwise_crc32(bytes.data() + start, size))
          << "start " << start << ", size " << size;
      const size_t split = size / 3;  // and continued from a running value that ends mid-word
      ASSERT_EQ(crc32(bytes.data() + start + split, size - split, crc32(bytes.data() + start, split)),
                bitwise_crc32(bytes.data() + start, size));
    }
}

}  // namespace
}  // namespace exitance::formats
