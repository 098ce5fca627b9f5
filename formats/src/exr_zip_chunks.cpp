#include "exr_zip_chunks.h"

#include <libdeflate.h>

#include <cstring>
#include <new>

namespace exitance::formats {

ExrZipChunkEncoder::ExrZipChunkEncoder(int level) : compressor_(libdeflate_alloc_compressor(level)) {
  if (!compressor_) throw std::bad_alloc();
}

ExrZipChunkEncoder::~ExrZipChunkEncoder() { libdeflate_free_compressor(compressor_); }

void ExrZipChunkEncoder::encode(const uint8_t* raw, size_t size, std::vector<uint8_t>& out) {
  // OpenEXR's preprocessing: even-indexed bytes to the first half, odd-indexed to the second (a
  // float's low and high bytes apart), then each byte replaced by its difference to the one before,
  // biased by 128 (a smooth channel becomes runs of small values).
  predicted_.resize(size);
  uint8_t* first = predicted_.data();
  uint8_t* second = predicted_.data() + (size + 1) / 2;
  for (size_t i = 0; i + 1 < size; i += 2) *first++ = raw[i], *second++ = raw[i + 1];
  if (size % 2 == 1) *first = raw[size - 1];
  for (size_t i = size; i-- > 1;) predicted_[i] = uint8_t(int(predicted_[i]) - int(predicted_[i - 1]) + 128);

  out.resize(libdeflate_zlib_compress_bound(compressor_, size));
  const size_t compressed = size == 0 ? 0 : libdeflate_zlib_compress(compressor_, predicted_.data(), size, out.data(), out.size());
  if (compressed == 0 || compressed >= size) {
    out.assign(raw, raw + size);
    return;
  }
  out.resize(compressed);
}

}  // namespace exitance::formats
