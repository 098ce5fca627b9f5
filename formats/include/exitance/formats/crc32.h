// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, init and final xor 0xFFFFFFFF): the same
// value as zlib's crc32() and `python3 -c "import zlib; print(zlib.crc32(data))"`.
// Written out rather than taken from zlib so the formats (and the loader an engine links) keep
// depending on the standard library and OpenEXR only.
#pragma once
#include <cstddef>
#include <cstdint>

namespace exitance::formats {

// Continues a running CRC: crc32(b, nb, crc32(a, na)) == crc32(a ++ b). Start with 0.
uint32_t crc32(const uint8_t* data, size_t size, uint32_t previous_crc = 0);

}  // namespace exitance::formats
