// Lightmap EXR pages written and read on OpenEXR's worker threads (formats::write_lightmap_exr,
// read_lightmap_exr): the file's bytes do not depend on the thread count, and every float reads
// back bit-identical, including -0, denormals, infinities and NaN payloads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <unistd.h>

#include "exitance/formats/lightmap_exr.h"

namespace fs = std::filesystem;
using exitance::formats::LightmapImage;

namespace {

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A page as assembly writes one (12 channels), odd-sized so the last ZIP block is partial, with
// noise in the colour channels, zero gutter and a few special values.
LightmapImage test_page(int width, int height) {
  LightmapImage image;
  image.width = width;
  image.height = height;
  uint32_t state = 12345u;
  auto next = [&] { return state = state * 1664525u + 1013904223u; };
  for (const char* name : {"R", "G", "B", "A", "valid", "error.Y", "direct.R", "direct.G", "direct.B", "indirect.R",
                           "indirect.G", "indirect.B"}) {
    std::vector<float>& data = image.channels[name];
    data.resize(size_t(width) * size_t(height));
    for (size_t i = 0; i < data.size(); ++i) {
      const bool gutter = (i / size_t(width)) % 7 == 3;
      data[i] = gutter ? 0.0f : float(next() % 100000) / 1000.0f;
    }
  }
  std::vector<float>& r = image.channels["R"];
  r[0] = -0.0f;
  r[1] = std::numeric_limits<float>::denorm_min();
  r[2] = std::numeric_limits<float>::infinity();
  const uint32_t nan_bits = 0x7fc01234u;
  std::memcpy(&r[3], &nan_bits, sizeof nan_bits);
  return image;
}

void expect_bit_identical(const LightmapImage& a, const LightmapImage& b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  ASSERT_EQ(a.channels.size(), b.channels.size());
  for (const auto& [name, data] : a.channels) {
    ASSERT_TRUE(b.channels.count(name)) << name;
    const std::vector<float>& other = b.channels.at(name);
    ASSERT_EQ(data.size(), other.size()) << name;
    EXPECT_EQ(std::memcmp(data.data(), other.data(), data.size() * sizeof(float)), 0) << name;
  }
}

}  // namespace

TEST(LightmapExr, ThreadCountChangesNeitherBytesNorPixels) {
  const fs::path dir = fs::temp_directory_path() / ("exitance_lightmap_exr_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const LightmapImage page = test_page(301, 133);
  EXPECT_GE(exitance::formats::lightmap_exr_threads(), 1);
  exitance::formats::write_lightmap_exr((dir / "serial.exr").string(), page, 0);
  const std::string serial = file_bytes(dir / "serial.exr");
  ASSERT_FALSE(serial.empty());
  for (int threads : {-1, 1, 2, 7}) {
    const fs::path path = dir / ("threads" + std::to_string(threads) + ".exr");
    exitance::formats::write_lightmap_exr(path.string(), page, threads);
    EXPECT_EQ(file_bytes(path), serial) << threads << " threads";
  }
  for (int threads : {0, -1, 3}) {
    SCOPED_TRACE(threads);
    expect_bit_identical(page, exitance::formats::read_lightmap_exr((dir / "serial.exr").string(), threads));
  }
  fs::remove_all(dir);
}
