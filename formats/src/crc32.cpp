#include "exitance/formats/crc32.h"

#include <algorithm>
#include <array>
#include <thread>
#include <vector>

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

uint32_t crc32_serial(const uint8_t* data, size_t size, uint32_t previous_crc) {
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

// GF(2) 32×32 matrices as 32 columns: the product with a vector, and a matrix's square.
uint32_t gf2_times(const uint32_t* matrix, uint32_t vector) {
  uint32_t sum = 0;
  for (; vector != 0; vector >>= 1, ++matrix)
    if (vector & 1u) sum ^= *matrix;
  return sum;
}

void gf2_square(uint32_t* square, const uint32_t* matrix) {
  for (int n = 0; n < 32; ++n) square[n] = gf2_times(matrix, matrix[n]);
}

}  // namespace

uint32_t crc32_combine(uint32_t crc_a, uint32_t crc_b, uint64_t size_b) {
  if (size_b == 0) return crc_a;
  uint32_t even[32], odd[32];  // the operator of 2^k zero bits, alternating between the two
  odd[0] = 0xEDB88320u;        // one zero bit
  for (int n = 1; n < 32; ++n) odd[n] = 1u << (n - 1);
  gf2_square(even, odd);  // two zero bits
  gf2_square(odd, even);  // four
  // Each pass squares to one zero byte, two, four, ... and applies the powers size_b has.
  for (;;) {
    gf2_square(even, odd);
    if (size_b & 1u) crc_a = gf2_times(even, crc_a);
    size_b >>= 1;
    if (size_b == 0) break;
    gf2_square(odd, even);
    if (size_b & 1u) crc_a = gf2_times(odd, crc_a);
    size_b >>= 1;
    if (size_b == 0) break;
  }
  return crc_a ^ crc_b;
}

uint32_t crc32(const uint8_t* data, size_t size, uint32_t previous_crc) {
  // scene.bin is tens to hundreds of MB, read and written whole: serially, the building's 67 MB
  // took 33 ms on a 2-core VM (17 ms in two pieces). Pieces of at least 4 MiB.
  const size_t threads = std::min<size_t>(std::max(1u, std::thread::hardware_concurrency()), size / (kCrc32ParallelFrom / 4));
  if (size < kCrc32ParallelFrom || threads < 2) return crc32_serial(data, size, previous_crc);
  const size_t piece = (size + threads - 1) / threads;  // the last piece may be shorter
  auto length = [&](size_t k) { return std::min(size, (k + 1) * piece) - k * piece; };
  std::vector<uint32_t> crcs(threads, 0);
  {
    std::vector<std::jthread> workers;
    workers.reserve(threads - 1);
    for (size_t k = 1; k < threads; ++k)
      workers.emplace_back([&, k] { crcs[k] = crc32_serial(data + k * piece, length(k), 0); });
    crcs[0] = crc32_serial(data, piece, previous_crc);
  }
  uint32_t crc = crcs[0];
  for (size_t k = 1; k < threads; ++k) crc = crc32_combine(crc, crcs[k], length(k));
  return crc;
}

}  // namespace exitance::formats
