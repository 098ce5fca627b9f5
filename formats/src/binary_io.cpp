#include "binary_io.h"

#include <cerrno>
#include <cstdio>
#include <memory>

namespace exitance::formats::binary_io {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

std::string errno_text() { return std::strerror(errno); }

}  // namespace

// stdio rather than iostreams: it reports why an open failed (errno) and refuses directories on read.
std::vector<uint8_t> read_whole_file(const std::string& path) {
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw FileAccessError(path + ": cannot open: " + errno_text());
  std::vector<uint8_t> bytes;
  uint8_t chunk[1 << 16];
  for (;;) {
    const size_t got = std::fread(chunk, 1, sizeof(chunk), file.get());
    bytes.insert(bytes.end(), chunk, chunk + got);
    if (got < sizeof(chunk)) break;
  }
  if (std::ferror(file.get())) throw FileAccessError(path + ": cannot read: " + errno_text());
  return bytes;
}

void write_whole_file(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
  if (!file) throw FileAccessError(path + ": cannot create: " + errno_text());
  if (std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size())
    throw FileAccessError(path + ": cannot write: " + errno_text());
  std::FILE* raw = file.release();
  if (std::fclose(raw) != 0) throw FileAccessError(path + ": cannot write: " + errno_text());
}

}  // namespace exitance::formats::binary_io
