#include "exitance/formats/crc32.h"

#include <array>

namespace exitance::formats {
namespace {

using Table = std::array<uint32_t, 256>;

// Slicing-by-8 (Intel's, as in zlib and Linux): table k holds the CRC of a byte followed by k zero
// bytes, so eight input bytes cost eight independent lookups instead of a chain of eight. The
// first table alone is the classic byte-at-a-time table. Several times faster on scene.bin's
// hundreds of megabytes; the value is the same (tests/formats/crc32_test.cpp checks both ways).
constexpr std::array<Table, 8> make_crc32_tables() {
  std::array<Table, 8> tables{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    tables[0][i] = c;
  }
  for (size_t k = 1; k < 8; ++k)
    for (uint32_t i = 0; i < 256; ++i) tables[k][i] = (tables[k - 1][i] >> 8) ^ tables[0][tables[k - 1][i] & 0xFFu];
  return tables;
}

constexpr std::array<Table, 8> kCrc32Tables = make_crc32_tables();

uint32_t load_le32(const uint8_t* p) {
  return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}

}  // namespace

uint32_t crc32(const uint8_t* data, size_t size, uint32_t previous_crc) {
  const auto& t = kCrc32Tables;
  uint32_t c = previous_crc ^ 0xFFFFFFFFu;
  for (; size >= 8; data += 8, size -= 8) {
    const uint32_t low = c ^ load_le32(data), high = load_le32(data + 4);
    c = t[7][low & 0xFFu] ^ t[6][(low >> 8) & 0xFFu] ^ t[5][(low >> 16) & 0xFFu] ^ t[4][low >> 24] ^
        t[3][high & 0xFFu] ^ t[2][(high >> 8) & 0xFFu] ^ t[1][(high >> 16) & 0xFFu] ^ t[0][high >> 24];
  }
  for (; size > 0; ++data, --size) c = t[0][(c ^ *data) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

}  // namespace exitance::formats
