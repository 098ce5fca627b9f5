// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, init and final xor 0xFFFFFFFF): the same
// value as zlib's crc32() and `python3 -c "import zlib; print(zlib.crc32(data))"`.
// Written out rather than taken from zlib so the formats (and the loader an engine links) keep
// depending on the standard library and OpenEXR only.
#pragma once
#include <cstddef>
#include <cstdint>

namespace exitance::formats {

// Continues a running CRC: crc32(b, nb, crc32(a, na)) == crc32(a ++ b). Start with 0.
// From kCrc32ParallelFrom bytes on, the data is cut into one piece per hardware thread (each at
// least a quarter of that), each piece's CRC taken on a thread of its own and the pieces combined
// (the same value).
uint32_t crc32(const uint8_t* data, size_t size, uint32_t previous_crc = 0);
inline constexpr size_t kCrc32ParallelFrom = size_t(16) << 20;

// The CRC of a ++ b from crc32(a) and crc32(b) of nb bytes (zlib's crc32_combine: b's length in
// zero bits applied to crc_a as a GF(2) matrix power, by squaring).
uint32_t crc32_combine(uint32_t crc_a, uint32_t crc_b, uint64_t size_b);

}  // namespace exitance::formats
