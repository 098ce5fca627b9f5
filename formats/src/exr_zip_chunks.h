// OpenEXR's ZIP chunk encoding (16 scanlines per chunk: its byte interleave, its delta predictor,
// then a zlib stream) done with libdeflate instead of OpenEXR 3.1's zlib: the same format, which
// every OpenEXR reader inflates, at about 0.6x zlib's CPU for the same or smaller output
// (bench/results/host-stages.md). write_lightmap_exr hands the results to OpenEXRCore as raw chunks.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

struct libdeflate_compressor;

namespace exitance::formats {

// OpenEXR's ZIP block height (ImfZipCompressor / internal_zip.c).
constexpr int kExrZipScanlines = 16;

class ExrZipChunkEncoder {
 public:
  explicit ExrZipChunkEncoder(int level);
  ~ExrZipChunkEncoder();
  ExrZipChunkEncoder(const ExrZipChunkEncoder&) = delete;
  ExrZipChunkEncoder& operator=(const ExrZipChunkEncoder&) = delete;

  // The bytes a ZIP chunk stores for `raw` (the chunk's scanlines, each its channels in the file's
  // order): the compressed stream, or `raw` itself where that is not smaller, as OpenEXR's writer
  // does (its readers take a chunk as uncompressed when its size is the unpacked size).
  void encode(const uint8_t* raw, size_t size, std::vector<uint8_t>& out);

 private:
  libdeflate_compressor* compressor_;
  std::vector<uint8_t> predicted_;
};

}  // namespace exitance::formats
