#include "png_strip.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <stdexcept>

// stb_image_write (Debian libstb-dev), compiled into this file and kept private to it, as
// exitance-view does (runtime/src/view/view_image_output.cpp).
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb_image_write.h>

namespace engine_sample {
namespace {

// The next lines are exitance-view's tone curve (runtime/src/view/view_image_output.cpp,
// tone_map_to_srgb8), rewritten here because an engine links no exitance-internal library: exposure,
// Reinhard on luminance (c / (1 + Y)), sRGB transfer, rounded to 8 bits. Same inputs, same bytes.
float srgb_encode(float x) { return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f; }

std::array<uint8_t, 3> tone_map_to_srgb8(const float linear[3], float exposure_ev) {
  const float scale = std::exp2(exposure_ev);
  float c[3] = {linear[0] * scale, linear[1] * scale, linear[2] * scale};
  for (float& v : c) v = std::isfinite(v) ? std::max(v, 0.0f) : (v > 0 ? 1e30f : 0.0f);
  const float luminance = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
  std::array<uint8_t, 3> out{};
  for (int i = 0; i < 3; ++i) {
    const float mapped = std::clamp(c[i] / (1.0f + luminance), 0.0f, 1.0f);
    out[size_t(i)] = uint8_t(std::lround(srgb_encode(mapped) * 255.0f));
  }
  return out;
}

}  // namespace

PngStrip::PngStrip(uint32_t frame_width, uint32_t frame_height, uint32_t frames, float exposure_ev)
    : width_(frame_width),
      height_(frame_height),
      frames_(frames),
      exposure_(exposure_ev),
      rgb_(size_t(frame_width) * frames * frame_height * 3, 0) {}

void PngStrip::put_frame(uint32_t frame, const std::vector<float>& rgba) {
  const size_t strip_width = size_t(width_) * frames_;
  for (uint32_t y = 0; y < height_; ++y)
    for (uint32_t x = 0; x < width_; ++x) {
      const std::array<uint8_t, 3> p = tone_map_to_srgb8(&rgba[(size_t(y) * width_ + x) * 4], exposure_);
      std::copy(p.begin(), p.end(),
                rgb_.begin() + ptrdiff_t((size_t(y) * strip_width + size_t(frame) * width_ + x) * 3));
    }
}

void PngStrip::write(const std::string& path) const {
  // Beside the output, so the rename stays on one file system and a failed run leaves no file.
  const std::filesystem::path final_path(path);
  std::string name = ".";  // appended piecewise: GCC 12 warns falsely about "." + std::string
  name += final_path.filename().string();
  name += ".tmp-" + std::to_string(::getpid());
  const std::filesystem::path temporary = final_path.parent_path() / name;
  const int strip_width = int(width_ * frames_);
  std::error_code ec;
  if (!stbi_write_png(temporary.c_str(), strip_width, int(height_), 3, rgb_.data(), strip_width * 3)) {
    std::filesystem::remove(temporary, ec);
    throw std::runtime_error(path + ": cannot write the PNG");
  }
  std::filesystem::rename(temporary, final_path, ec);
  if (ec) {
    const std::string why = ec.message();
    std::filesystem::remove(temporary, ec);
    throw std::runtime_error(path + ": cannot rename the PNG into place (" + why + ")");
  }
}

}  // namespace engine_sample
