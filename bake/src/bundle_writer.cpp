#include "exitance/bake/bundle_writer.h"

#include <openssl/evp.h>
#include <unistd.h>

#include <fstream>
#include <memory>
#include <stdexcept>

namespace exitance {

namespace fs = std::filesystem;

void write_bundle_atomically(const fs::path& out_dir, const std::function<void(const fs::path&)>& write_contents) {
  const fs::path target = fs::absolute(out_dir).lexically_normal();
  const std::string suffix = std::to_string(::getpid());
  const fs::path temporary = target.parent_path() / (target.filename().string() + ".tmp-" + suffix);
  const fs::path previous = target.parent_path() / (target.filename().string() + ".old-" + suffix);
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  fs::remove_all(temporary, ec);
  if (!fs::create_directory(temporary, ec))
    throw std::runtime_error("cannot create " + temporary.string() + ": " + ec.message());
  try {
    write_contents(temporary);
    if (fs::exists(target)) fs::rename(target, previous);
    fs::rename(temporary, target);
    fs::remove_all(previous, ec);
  } catch (...) {
    fs::remove_all(temporary, ec);
    if (!fs::exists(target) && fs::exists(previous)) fs::rename(previous, target, ec);
    throw;
  }
}

std::string sha256_of_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr);
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    EVP_DigestUpdate(context.get(), buffer.data(), size_t(in.gcount()));
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(context.get(), digest, &length);
  static const char* hex = "0123456789abcdef";
  std::string text;
  for (unsigned i = 0; i < length; ++i) text += {hex[digest[i] >> 4], hex[digest[i] & 15]};
  return text;
}

}  // namespace exitance
