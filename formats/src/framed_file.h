// The framing probes.bin, svo.bin and scene.bin share (probes_format.md, svo_format.md,
// scene_format.md): an 8-byte magic, a u32 format version, a u32 header size, format-specific header fields, then the last 16 header
// bytes are the u64 payload size, the CRC-32 of the payload and the CRC-32 of the header bytes
// before it; the payload follows the header and ends the file.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace exitance::formats::framing {

struct FileKind {
  const char* magic;  // 8 bytes, may contain NULs
  uint32_t version;  // the newest version; build_frame writes it
  uint32_t header_size;
  uint32_t oldest_version = 0;  // the oldest version readers still accept; 0: only `version`
};

struct FramedView {
  const uint8_t* header;  // header_size bytes
  const uint8_t* payload;
  uint64_t payload_size;
  uint32_t version;  // the file's format version, oldest_version .. version
};

// Checks, in this order, and throws FormatError naming the first problem: enough bytes for the
// magic, the magic, the version (older / newer), the header size, enough bytes for the header,
// the header CRC, the payload size against the file size (truncated or trailing bytes), the
// payload CRC. Fuzzing builds (FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION) skip the two CRC
// comparisons so the fuzzer reaches the structural checks behind them.
FramedView open_frame(const uint8_t* data, size_t size, const FileKind& kind, const std::string& name);

// header_fields: the bytes from offset 16 up to header_size - 16 (after magic, version and size).
std::vector<uint8_t> build_frame(const FileKind& kind, const std::vector<uint8_t>& header_fields,
                                 const std::vector<uint8_t>& payload);

// The same frame built in place, for large payloads (no copy of the payload): `file` starts as
// begin_frame's header_size placeholder bytes, the caller appends the payload, and finish_frame
// writes the header over the placeholder.
std::vector<uint8_t> begin_frame(const FileKind& kind, size_t payload_capacity);
void finish_frame(const FileKind& kind, const std::vector<uint8_t>& header_fields, std::vector<uint8_t>& file);

}  // namespace exitance::formats::framing
