// Lightmap EXR pages written on worker threads (formats::write_lightmap_exr: ZIP chunks deflated by
// libdeflate, formats/src/exr_zip_chunks.h) and read by OpenEXR's own reader on its worker threads
// (read_lightmap_exr): the file's bytes do not depend on the thread count, and every float reads
// back bit-identical, including -0, denormals, infinities and NaN payloads, in chunks that deflate
// and in chunks stored raw because they do not.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <utility>

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
  if (r.size() < 4) return image;  // too small for the special values
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

// Random bit patterns do not deflate: such chunks are stored as they are (OpenEXR's rule, which its
// reader recognises by the chunk's size). Sizes down to one pixel and one partial chunk.
TEST(LightmapExr, IncompressibleAndTinyPagesReadBackBitIdentical) {
  const fs::path dir = fs::temp_directory_path() / ("exitance_lightmap_exr_raw_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const auto& [width, height] : {std::pair{257, 41}, {1, 1}, {3, 17}, {64, 16}}) {
    SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height));
    LightmapImage page = test_page(width, height);
    uint64_t state = 0x9E3779B97F4A7C15ull;
    for (auto& [name, data] : page.channels)
      for (size_t i = name == "R" ? 4 : 0; i < data.size(); ++i) {  // R keeps its special values
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        const uint32_t bits = uint32_t(state >> 16);
        std::memcpy(&data[i], &bits, sizeof bits);
      }
    const fs::path path = dir / "page.exr";
    exitance::formats::write_lightmap_exr(path.string(), page, 3);
    const std::string bytes = file_bytes(path);
    // Every chunk stored raw: the file holds at least every pixel's bytes.
    EXPECT_GE(bytes.size(), size_t(width) * size_t(height) * page.channels.size() * sizeof(float));
    expect_bit_identical(page, exitance::formats::read_lightmap_exr(path.string(), 0));
    exitance::formats::write_lightmap_exr(path.string(), page, 0);
    EXPECT_EQ(file_bytes(path), bytes);
  }
  fs::remove_all(dir);
}

// A page that cannot be written throws one message naming the file and leaves no file behind.
TEST(LightmapExr, AFailedWriteNamesTheFileAndLeavesNothing) {
  const fs::path dir = fs::temp_directory_path() / ("exitance_lightmap_exr_bad_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path missing = dir / "no_such_folder" / "lightmap-0.exr";
  try {
    exitance::formats::write_lightmap_exr(missing.string(), test_page(8, 8));
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
  LightmapImage wrong = test_page(8, 8);
  wrong.channels["B"].pop_back();
  const fs::path path = dir / "lightmap-1.exr";
  try {
    exitance::formats::write_lightmap_exr(path.string(), wrong);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("channel B"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(missing));
  fs::remove_all(dir);
}
