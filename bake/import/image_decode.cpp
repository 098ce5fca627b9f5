#include "exitance/bake/import/image_decode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <cstdio>

#include "exitance/bake/input_error.h"

namespace exitance {
namespace {

constexpr long long kMaxTexels = 1ll << 27;  // 128 M texels: larger is a hostile header, not a texture

// OIIO 2.4's PNG reader installs an error handler that records the message for geterror() and then
// *returns*; libpng treats a returning handler as "not handled" and falls back to png_default_error,
// which fprintf()s "libpng error: ..." to the C stderr stream before longjmp-ing. No OIIO attribute
// turns that off, so while OIIO decodes, the C `stderr` stream points at /dev/null. Only the stdio
// stream is swapped: file descriptor 2 is untouched, so sanitizer reports (written straight to the
// descriptor) and our own std::cerr output still appear. The errors reach the user through
// geterror(), in our one-line InputError.
class QuietCStderr {
 public:
  QuietCStderr() : saved_(stderr), sink_(std::fopen("/dev/null", "w")) {
    if (!sink_) return;
    std::fflush(saved_);
    stderr = sink_;
  }
  ~QuietCStderr() {
    if (!sink_) return;
    stderr = saved_;
    std::fclose(sink_);
  }
  QuietCStderr(const QuietCStderr&) = delete;
  QuietCStderr& operator=(const QuietCStderr&) = delete;

 private:
  FILE* saved_;
  FILE* sink_;
};

// Walks a PNG's chunk list without decoding anything: every chunk must lie inside the bytes and the
// list must reach IEND. OIIO 2.4's PNG read callback, on running out of data, builds a std::string
// and calls png_error, whose longjmp skips that string's destructor (a leak LeakSanitizer reports);
// with a complete chunk list libpng never asks for bytes past the end, so that path is never taken.
// Returns an empty string when the structure is sound, otherwise the problem.
std::string png_structure_problem(const std::vector<unsigned char>& bytes) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 8 || !std::equal(kSignature, kSignature + 8, bytes.begin())) return "";  // not a PNG
  auto be32 = [&](size_t at) {
    return uint32_t(bytes[at]) << 24 | uint32_t(bytes[at + 1]) << 16 | uint32_t(bytes[at + 2]) << 8 | bytes[at + 3];
  };
  size_t offset = 8;
  for (int chunk = 0;; ++chunk) {
    if (bytes.size() - offset < 12) return "PNG data is truncated (chunk " + std::to_string(chunk) + " is incomplete)";
    const uint64_t length = be32(offset);
    if (length > 0x7fffffffu || length > bytes.size() - offset - 12)
      return "PNG data is truncated or corrupt (chunk " + std::to_string(chunk) + " of " + std::to_string(length) +
             " bytes runs past the end)";
    if (std::memcmp(bytes.data() + offset + 4, "IEND", 4) == 0) return "";
    offset += 12 + size_t(length);
  }
}

// OIIO joins several messages with newlines; the contract is one error line.
std::string one_line(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

Texture read_all(OIIO::ImageInput& input, const std::string& file, const std::string& element) {
  const OIIO::ImageSpec& spec = input.spec();
  if (spec.width <= 0 || spec.height <= 0 || (long long)spec.width * spec.height > kMaxTexels || spec.nchannels <= 0)
    throw InputError(file, element, "image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                        " is not plausible");
  std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  if (!input.read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw InputError(file, element, "image data does not decode (" + one_line(input.geterror()) + ")");
  Texture texture;
  texture.width = spec.width;
  texture.height = spec.height;
  texture.rgb.resize(size_t(spec.width) * size_t(spec.height) * 3);
  const size_t n = size_t(spec.nchannels);
  for (size_t i = 0; i < size_t(spec.width) * size_t(spec.height); ++i)
    for (size_t c = 0; c < 3; ++c) {
      // Grey (1-2 channel) images replicate their first channel.
      float v = pixels[i * n + (n >= 3 ? c : 0)];
      texture.rgb[i * 3 + c] = std::isfinite(v) ? v : 0.0f;
    }
  // Alpha is the 4th channel (RGBA) or the 2nd (grey + alpha); linear, not sRGB-encoded.
  if (n == 4 || n == 2) {
    texture.alpha.resize(size_t(spec.width) * size_t(spec.height));
    for (size_t i = 0; i < texture.alpha.size(); ++i) {
      const float a = pixels[i * n + n - 1];
      texture.alpha[i] = std::isfinite(a) ? std::clamp(a, 0.0f, 1.0f) : 1.0f;
    }
  }
  return texture;
}

}  // namespace

namespace {

Texture decode_image(const std::vector<unsigned char>& bytes, const std::string& name_hint, const std::string& file,
                     const std::string& element, bool srgb) {
  if (bytes.empty()) throw InputError(file, element, "image has no data");
  if (const std::string problem = png_structure_problem(bytes); !problem.empty())
    throw InputError(file, element, problem);
  OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
  const QuietCStderr quiet;
  auto input = OIIO::ImageInput::open(name_hint, nullptr, &reader);
  if (!input) throw InputError(file, element, "image data does not decode (" + one_line(OIIO::geterror()) + ")");
  const bool is_float = input->spec().format.is_floating_point();
  Texture texture = read_all(*input, file, element);
  if (srgb && !is_float)
    for (float& v : texture.rgb) v = srgb_to_linear(std::clamp(v, 0.0f, 1.0f));
  return texture;
}

}  // namespace

Texture decode_srgb_image(const std::vector<unsigned char>& bytes, const std::string& name_hint,
                          const std::string& file, const std::string& element) {
  return decode_image(bytes, name_hint, file, element, true);
}

Texture decode_data_image(const std::vector<unsigned char>& bytes, const std::string& name_hint,
                          const std::string& file, const std::string& element) {
  return decode_image(bytes, name_hint, file, element, false);
}

Texture read_linear_image_file(const std::string& path, const std::string& element) {
  const QuietCStderr quiet;
  auto input = OIIO::ImageInput::open(path);
  if (!input) throw InputError(path, element, "cannot read image (" + one_line(OIIO::geterror()) + ")");
  Texture texture = read_all(*input, path, element);
  for (float& v : texture.rgb) v = std::max(v, 0.0f);
  texture.alpha.clear();  // a sky has no coverage
  return texture;
}

}  // namespace exitance
