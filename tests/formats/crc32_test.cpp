// CRC-32 against the IEEE check value and its incremental form.
#include <gtest/gtest.h>

#include <algorithm>
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

TEST(Crc32, CombinesTwoPiecesIntoTheWholesCrc) {
  std::vector<uint8_t> bytes(1000);
  uint32_t state = 777;
  for (uint8_t& b : bytes) b = uint8_t((state = state * 1664525u + 1013904223u) >> 24);
  for (size_t split : {size_t(0), size_t(1), size_t(7), size_t(8), size_t(333), size_t(999), size_t(1000)})
    ASSERT_EQ(crc32_combine(crc32(bytes.data(), split), crc32(bytes.data() + split, bytes.size() - split),
                            bytes.size() - split),
              bitwise_crc32(bytes.data(), bytes.size()))
        << "split " << split;
}

// Past kCrc32ParallelFrom the pieces are taken on threads and combined: the same value as the
// serial definition continued over pieces below the threshold, also from a running value.
TEST(Crc32, ALargeBufferInPiecesOnThreadsGivesTheSerialValue) {
  const size_t size = kCrc32ParallelFrom * 2 + 12345;  // pieces of unequal length, a tail mid-word
  std::vector<uint8_t> bytes(size);
  uint32_t state = 99;
  for (uint8_t& b : bytes) b = uint8_t((state = state * 1664525u + 1013904223u) >> 24);
  const size_t step = kCrc32ParallelFrom / 2 - 3;  // serial calls, continued
  auto serial = [&](size_t begin, uint32_t running) {
    for (size_t at = begin; at < size; at += step) running = crc32(bytes.data() + at, std::min(step, size - at), running);
    return running;
  };
  EXPECT_EQ(crc32(bytes.data(), size), serial(0, 0));
  const uint32_t head = crc32(bytes.data(), 5);
  EXPECT_EQ(crc32(bytes.data() + 5, size - 5, head), serial(5, head));
  EXPECT_EQ(crc32(bytes.data(), size), crc32_combine(crc32(bytes.data(), 5), crc32(bytes.data() + 5, size - 5), size - 5));
}

}  // namespace
}  // namespace exitance::formats
