// SHA-256 over a stream of values (OpenSSL's EVP digest): the cache keys and the input hash.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

struct evp_md_ctx_st;

namespace exitance {

class Sha256Stream {
 public:
  Sha256Stream();
  ~Sha256Stream();
  Sha256Stream(const Sha256Stream&) = delete;
  Sha256Stream& operator=(const Sha256Stream&) = delete;

  void bytes(const void* data, size_t size);
  // A length-prefixed string, so ("ab", "c") and ("a", "bc") differ.
  void text(std::string_view s);
  template <class T>
  void value(const T& v) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>, "hash fields one by one, not structs with padding");
    bytes(&v, sizeof v);
  }
  // A length-prefixed array of arithmetic values or of padding-free vector types (Vec2, Vec3).
  template <class T>
  void array(const std::vector<T>& values) {
    static_assert(std::has_unique_object_representations_v<T> || std::is_floating_point_v<T> ||
                      (std::is_trivially_copyable_v<T> && sizeof(T) % sizeof(float) == 0),
                  "array elements must have no padding");
    value(uint64_t(values.size()));
    bytes(values.data(), values.size() * sizeof(T));
  }
  // Lower-case hex of the digest; the stream cannot be used afterwards.
  std::string hex();

 private:
  evp_md_ctx_st* context_;
};

// SHA-256 of a file's bytes, lower-case hex. Throws std::runtime_error when it cannot be read.
std::string sha256_of_file(const std::string& path);

}  // namespace exitance
