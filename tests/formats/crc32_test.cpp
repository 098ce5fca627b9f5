// CRC-32 against the IEEE check value and its incremental form.
#include <gtest/gtest.h>

#include <string>

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

}  // namespace
}  // namespace exitance::formats
