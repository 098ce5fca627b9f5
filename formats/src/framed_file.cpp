#include "framed_file.h"

#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "binary_io.h"
#include "exitance/formats/crc32.h"
#include "exitance/formats/huge_pages.h"
#include "exitance/formats/format_error.h"

namespace exitance::formats::framing {
namespace {

constexpr size_t kMagicSize = 8;
constexpr size_t kTrailerSize = 16;  // payload size, payload CRC, header CRC

#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr bool kCheckCrc = false;
#else
constexpr bool kCheckCrc = true;
#endif

std::string hex32(uint32_t v) {
  char text[11];
  std::snprintf(text, sizeof(text), "0x%08x", v);
  return text;
}

}  // namespace

FramedView open_frame(const uint8_t* data, size_t size, const FileKind& kind, const std::string& name) {
  if (data == nullptr && size != 0) throw FormatError(name + ": no data");
  if (size < kMagicSize) throw FormatError(name + ": truncated: " + std::to_string(size) + " bytes, shorter than the magic");
  if (std::memcmp(data, kind.magic, kMagicSize) != 0) throw FormatError(name + ": not this kind of file (wrong magic)");
  binary_io::LittleEndianReader reader(data, size, name);
  reader.skip(kMagicSize);
  if (size < 16) throw FormatError(name + ": truncated: " + std::to_string(size) + " bytes, header needs " + std::to_string(kind.header_size));
  const uint32_t version = reader.u32();
  if (version > kind.version)
    throw FormatError(name + ": format version " + std::to_string(version) + " is newer than this loader (" +
                      std::to_string(kind.version) + ")");
  const uint32_t oldest = kind.oldest_version != 0 ? kind.oldest_version : kind.version;
  if (version < oldest)
    throw FormatError(name + ": format version " + std::to_string(version) + " is older than this loader supports (" +
                      std::to_string(oldest) + ")");
  const uint32_t header_size = reader.u32();
  if (header_size != kind.header_size)
    throw FormatError(name + ": header: size " + std::to_string(header_size) + " is not " +
                      std::to_string(kind.header_size) + " as version " + std::to_string(version) + " requires");
  if (size < header_size)
    throw FormatError(name + ": truncated: " + std::to_string(size) + " bytes, header needs " + std::to_string(header_size));

  binary_io::LittleEndianReader trailer(data + header_size - kTrailerSize, kTrailerSize, name);
  const uint64_t payload_size = trailer.u64();
  const uint32_t payload_crc = trailer.u32();
  const uint32_t header_crc = trailer.u32();
  const uint32_t actual_header_crc = crc32(data, header_size - 4);
  if (kCheckCrc && actual_header_crc != header_crc)
    throw FormatError(name + ": header: checksum " + hex32(actual_header_crc) + " does not match the stored " +
                      hex32(header_crc) + " (corrupt header)");
  const uint64_t available = uint64_t(size) - header_size;
  if (payload_size > available)
    throw FormatError(name + ": truncated: payload needs " + std::to_string(payload_size) + " bytes, file has " +
                      std::to_string(available) + " after the header");
  if (payload_size < available)
    throw FormatError(name + ": " + std::to_string(available - payload_size) + " unexpected bytes after the payload");
  const uint8_t* payload = data + header_size;
  const uint32_t actual_payload_crc = crc32(payload, size_t(payload_size));
  if (kCheckCrc && actual_payload_crc != payload_crc)
    throw FormatError(name + ": payload: checksum " + hex32(actual_payload_crc) + " does not match the stored " +
                      hex32(payload_crc) + " (corrupt data)");
  return {data, payload, payload_size, version};
}

std::vector<uint8_t> build_frame(const FileKind& kind, const std::vector<uint8_t>& header_fields,
                                 const std::vector<uint8_t>& payload) {
  if (16 + header_fields.size() + kTrailerSize != kind.header_size)
    throw std::logic_error("framing: header fields do not fill the header");
  std::vector<uint8_t> bytes;
  bytes.reserve(kind.header_size + payload.size());
  binary_io::LittleEndianWriter out(bytes);
  out.bytes(kind.magic, kMagicSize);
  out.u32(kind.version);
  out.u32(kind.header_size);
  out.bytes(header_fields.data(), header_fields.size());
  out.u64(payload.size());
  out.u32(crc32(payload.data(), payload.size()));
  out.u32(crc32(bytes.data(), bytes.size()));
  out.bytes(payload.data(), payload.size());
  return bytes;
}

std::vector<uint8_t> begin_frame(const FileKind& kind, size_t payload_capacity) {
  std::vector<uint8_t> file;
  file.reserve(kind.header_size + payload_capacity);
  advise_huge_pages(file.data(), file.capacity());  // tens of MB written once (huge_pages.h)
  file.resize(kind.header_size, 0);
  return file;
}

void finish_frame(const FileKind& kind, const std::vector<uint8_t>& header_fields, std::vector<uint8_t>& file) {
  if (16 + header_fields.size() + kTrailerSize != kind.header_size)
    throw std::logic_error("framing: header fields do not fill the header");
  if (file.size() < kind.header_size) throw std::logic_error("framing: the file has no room for its header");
  std::vector<uint8_t> header;
  header.reserve(kind.header_size);
  binary_io::LittleEndianWriter out(header);
  out.bytes(kind.magic, kMagicSize);
  out.u32(kind.version);
  out.u32(kind.header_size);
  out.bytes(header_fields.data(), header_fields.size());
  const size_t payload_size = file.size() - kind.header_size;
  out.u64(payload_size);
  out.u32(crc32(file.data() + kind.header_size, payload_size));
  out.u32(crc32(header.data(), header.size()));
  std::memcpy(file.data(), header.data(), header.size());
}

}  // namespace exitance::formats::framing
