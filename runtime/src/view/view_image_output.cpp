#include "exitance/runtime/view/view_image_output.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/view/view_input_error.h"

// stb_image_write (Debian libstb-dev): the PNG encoder; OpenEXR has none and the tool links no
// OpenImageIO (DESIGN §2).
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb_image_write.h>

namespace exitance::view {
namespace fs = std::filesystem;

namespace {

std::string lowercase_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// Beside the output, so the final rename stays on one file system.
std::string temporary_path_for(const std::string& path) {
  const fs::path p(path);
  std::string name = ".";  // appended piecewise: GCC 12 warns falsely about "." + std::string
  name += p.filename().string();
  name += ".tmp-" + std::to_string(::getpid());
  return (p.parent_path() / name).string();
}

float srgb_encode(float x) { return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f; }

void write_exr(const std::string& path, const ViewImage& image) {
  formats::LightmapImage exr;
  exr.width = image.width;
  exr.height = image.height;
  const size_t n = size_t(image.width) * size_t(image.height);
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    std::vector<float>& channel = exr.channels[names[c]];
    channel.resize(n);
    for (size_t i = 0; i < n; ++i) channel[i] = image.rgb[i * 3 + size_t(c)];
  }
  formats::write_lightmap_exr(path, exr);
}

// False when stb cannot write the file.
bool write_png(const std::string& path, const ViewImage& image, float exposure_ev) {
  std::vector<uint8_t> bytes(size_t(image.width) * size_t(image.height) * 3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::array<uint8_t, 3> p = tone_map_to_srgb8(image.pixel(x, y), exposure_ev);
      std::copy(p.begin(), p.end(), bytes.begin() + (ptrdiff_t(y) * image.width + x) * 3);
    }
  return stbi_write_png(path.c_str(), image.width, image.height, 3, bytes.data(), image.width * 3) != 0;
}

}  // namespace

ViewImageFormat view_image_format(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".exr") return ViewImageFormat::Exr;
  if (ext == ".png") return ViewImageFormat::Png;
  throw ViewInputError("-o: " + path + ": the output must end in .exr (linear) or .png (tone-mapped)");
}

void check_view_output_writable(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw ViewInputError("-o: " + path + ": is a folder");
  const fs::path folder = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  if (!fs::is_directory(folder, ec)) throw ViewInputError("-o: " + path + ": folder " + folder.string() + " does not exist");
  const std::string probe = temporary_path_for(path);
  std::FILE* f = std::fopen(probe.c_str(), "wb");
  if (!f) throw ViewInputError("-o: " + path + ": cannot create a file in " + folder.string());
  std::fclose(f);
  fs::remove(probe, ec);
}

std::array<uint8_t, 3> tone_map_to_srgb8(Vec3 linear, float exposure_ev) {
  const float scale = std::exp2(exposure_ev);
  float c[3] = {linear.x * scale, linear.y * scale, linear.z * scale};
  for (float& v : c) v = std::isfinite(v) ? std::max(v, 0.0f) : (v > 0 ? 1e30f : 0.0f);
  const float luminance = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
  std::array<uint8_t, 3> out{};
  for (int i = 0; i < 3; ++i) {
    const float mapped = std::clamp(c[i] / (1.0f + luminance), 0.0f, 1.0f);
    out[size_t(i)] = uint8_t(std::lround(srgb_encode(mapped) * 255.0f));
  }
  return out;
}

void write_view_image(const std::string& path, const ViewImage& image, float exposure_ev) {
  const ViewImageFormat format = view_image_format(path);
  const std::string temporary = temporary_path_for(path);
  std::error_code ec;
  try {
    if (format == ViewImageFormat::Exr)
      write_exr(temporary, image);
    else if (!write_png(temporary, image, exposure_ev))
      throw std::runtime_error("the PNG encoder failed");
    fs::rename(temporary, path);
  } catch (const std::exception& e) {
    fs::remove(temporary, ec);
    throw ViewInputError(path + ": cannot write (" + e.what() + ")");
  }
}

}  // namespace exitance::view
