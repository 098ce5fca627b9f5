// Little-endian field (de)serialisation and whole-file I/O shared by probes_file.cpp,
// svo_file.cpp and scene_file.cpp. Fields are assembled byte by byte so the files are the same on any host and no
// struct layout or alignment leaks into the format.
#pragma once
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "exitance/formats/format_error.h"

namespace exitance::formats::binary_io {

class LittleEndianWriter {
 public:
  explicit LittleEndianWriter(std::vector<uint8_t>& out) : out_(out) {}
  // resize + memcpy rather than vector::insert, which trips a GCC 12 -Wstringop-overflow false positive.
  void bytes(const void* data, size_t size) {
    if (size == 0) return;
    const size_t old_size = out_.size();
    out_.resize(old_size + size);
    std::memcpy(out_.data() + old_size, data, size);
  }
  void u8(uint8_t v) { out_.push_back(v); }
  void u16(uint16_t v) { for (int i = 0; i < 2; ++i) out_.push_back(uint8_t(v >> (8 * i))); }
  void u32(uint32_t v) { for (int i = 0; i < 4; ++i) out_.push_back(uint8_t(v >> (8 * i))); }
  void u64(uint64_t v) { for (int i = 0; i < 8; ++i) out_.push_back(uint8_t(v >> (8 * i))); }
  void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<uint64_t>(v)); }
  // `count` values made of 4-byte fields (u32, f32, arrays of them), each field little-endian, as
  // u32()/f32() one by one would write them: one copy on a little-endian host.
  template <class T>
  void words(const T* values, size_t count) {
    static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % 4 == 0, "whole 4-byte fields only");
    if constexpr (std::endian::native == std::endian::little) {
      bytes(values, count * sizeof(T));
    } else {
      const auto* raw = reinterpret_cast<const uint8_t*>(values);
      for (size_t k = 0; k < count * sizeof(T) / 4; ++k) {
        uint32_t field;
        std::memcpy(&field, raw + 4 * k, 4);
        u32(field);
      }
    }
  }

 private:
  std::vector<uint8_t>& out_;
};

// Reads fields from a span whose length the caller has already checked; still bounds-checks every
// read so a mistake in that check becomes a FormatError, not an out-of-bounds read.
class LittleEndianReader {
 public:
  LittleEndianReader(const uint8_t* data, size_t size, const std::string& name)
      : data_(data), size_(size), name_(name) {}
  uint8_t u8() { return *take(1); }
  uint16_t u16() {
    const uint8_t* p = take(2);
    return uint16_t(p[0] | (p[1] << 8));
  }
  uint32_t u32() {
    const uint8_t* p = take(4);
    return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
  }
  uint64_t u64() {
    const uint64_t low = u32();
    return low | (uint64_t(u32()) << 32);
  }
  float f32() { return std::bit_cast<float>(u32()); }
  double f64() { return std::bit_cast<double>(u64()); }
  // n bytes as a string (the caller checks n against its limit first).
  std::string text(size_t n) {
    const uint8_t* p = take(n);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  // `count` values made of 4-byte fields, as the writer's words() wrote them: one bounds check and
  // one copy on a little-endian host (scene.bin's arrays are tens of MB), else field by field.
  template <class T>
  void words(T* values, size_t count) {
    static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % 4 == 0, "whole 4-byte fields only");
    if (count > remaining() / sizeof(T)) throw FormatError(name_ + ": unexpected end of data at byte " + std::to_string(position_));
    if constexpr (std::endian::native == std::endian::little) {
      if (count > 0) std::memcpy(static_cast<void*>(values), take(count * sizeof(T)), count * sizeof(T));
    } else {
      auto* raw = reinterpret_cast<uint8_t*>(values);
      for (size_t k = 0; k < count * sizeof(T) / 4; ++k) {
        const uint32_t field = u32();
        std::memcpy(raw + 4 * k, &field, 4);
      }
    }
  }
  size_t remaining() const { return size_ - position_; }
  void skip(size_t n) { take(n); }
  size_t position() const { return position_; }

 private:
  const uint8_t* take(size_t n) {
    if (n > size_ - position_) throw FormatError(name_ + ": unexpected end of data at byte " + std::to_string(position_));
    const uint8_t* p = data_ + position_;
    position_ += n;
    return p;
  }
  const uint8_t* data_;
  size_t size_;
  size_t position_ = 0;
  const std::string& name_;
};

// Whole file into memory; throws FileAccessError when it cannot be opened or read.
std::vector<uint8_t> read_whole_file(const std::string& path);
// Throws FileAccessError when the file cannot be written completely.
void write_whole_file(const std::string& path, const std::vector<uint8_t>& bytes);

}  // namespace exitance::formats::binary_io
