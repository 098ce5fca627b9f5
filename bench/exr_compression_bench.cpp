// A lightmap page written with each of OpenEXR's compressions that keep float channels exact, and by
// formats::write_lightmap_exr (ZIP chunks deflated by libdeflate), on 1..N threads: file size, write and read seconds (medians), and whether every channel reads
// back bit-identical (bench/results/host-stages.md, the choice of formats::write_lightmap_exr).
//
//   bench_exr_compression PAGE.exr [--threads 1,2] [--repeat 3] [--tmp DIR]
#include <CLI/CLI.hpp>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfThreading.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"

#include "wall_clock.h"

using exitance::bench::cpu_seconds;
using exitance::bench::median;
using exitance::bench::seconds_since;

namespace {

void write_with(const std::string& path, const exitance::formats::LightmapImage& image, Imf::Compression compression, int zip_level,
                int threads) {
  Imf::Header header(image.width, image.height);
  header.compression() = compression;
  if (zip_level >= 0) header.zipCompressionLevel() = zip_level;
  Imf::FrameBuffer frame;
  for (const auto& [name, data] : image.channels) {
    header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    frame.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(data.data())), sizeof(float),
                                  sizeof(float) * size_t(image.width)));
  }
  Imf::OutputFile file(path.c_str(), header, threads);
  file.setFrameBuffer(frame);
  file.writePixels(image.height);
}

bool bit_identical(const exitance::formats::LightmapImage& a, const exitance::formats::LightmapImage& b) {
  if (a.width != b.width || a.height != b.height || a.channels.size() != b.channels.size()) return false;
  for (const auto& [name, data] : a.channels) {
    auto it = b.channels.find(name);
    if (it == b.channels.end() || it->second.size() != data.size() ||
        std::memcmp(it->second.data(), data.data(), data.size() * sizeof(float)) != 0)
      return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lossless OpenEXR compressions of a lightmap page: size, write and read seconds"};
  std::string page, tmp = "/tmp";
  std::vector<int> thread_counts = {1, 2};
  uint32_t repeat = 3;
  app.add_option("page", page)->required();
  app.add_option("--threads", thread_counts, "OpenEXR thread counts to try (0 = on the calling thread)")->delimiter(',');
  app.add_option("--repeat", repeat)->check(CLI::PositiveNumber);
  app.add_option("--tmp", tmp, "folder for the files written");
  std::string only;
  app.add_option("--only", only, "only the compressions whose name starts with this (e.g. ZIP)");
  CLI11_PARSE(app, argc, argv);

  const exitance::formats::LightmapImage image = exitance::formats::read_lightmap_exr(page);
  const double raw = double(image.width) * image.height * image.channels.size() * sizeof(float);
  int most = 0;
  for (int t : thread_counts) most = std::max(most, t);
  Imf::setGlobalThreadCount(most);
  struct Choice {
    const char* name;
    Imf::Compression compression;
    int zip_level;  // -1: the header's default
    bool shipped = false;  // formats::write_lightmap_exr: ZIP chunks deflated by libdeflate
  };
  // PXR24 rounds float to 24 bits and B44 leaves float uncompressed: not in the list. DWAA/DWAB
  // quantize only HALF channels; FLOAT ones go through zlib losslessly (checked below anyway).
  const Choice choices[] = {{"NONE", Imf::NO_COMPRESSION, -1}, {"RLE", Imf::RLE_COMPRESSION, -1},
                            {"ZIPS", Imf::ZIPS_COMPRESSION, -1}, {"ZIP level 1", Imf::ZIP_COMPRESSION, 1},
                            {"ZIP level 2", Imf::ZIP_COMPRESSION, 2}, {"ZIP level 4 (OpenEXR 3.1's default)", Imf::ZIP_COMPRESSION, -1},
                            {"ZIP level 6", Imf::ZIP_COMPRESSION, 6}, {"ZIP level 9", Imf::ZIP_COMPRESSION, 9},
                            {"PIZ", Imf::PIZ_COMPRESSION, -1}, {"DWAA", Imf::DWAA_COMPRESSION, -1},
                            {"DWAB", Imf::DWAB_COMPRESSION, -1},
                            {"ZIP by libdeflate (write_lightmap_exr)", Imf::ZIP_COMPRESSION, -1, true}};
  std::printf("%s: %dx%d, %zu float channels, %.1f MB raw; medians of %u\n", page.c_str(), image.width, image.height,
              image.channels.size(), raw / 1e6, repeat);
  std::printf("| compression | threads | MB | ratio | write s | write CPU s | read s | bit-identical |\n|---|---|---|---|---|---|---|---|\n");
  const std::string path = (std::filesystem::path(tmp) / "exr_compression_bench.exr").string();
  for (const Choice& c : choices) {
    if (std::string(c.name).rfind(only, 0) != 0) continue;
    for (int threads : thread_counts) {
      std::vector<double> write, read, write_cpu;
      bool same = true;
      for (uint32_t r = 0; r < repeat; ++r) {
        auto start = std::chrono::steady_clock::now();
        const double cpu_start = cpu_seconds();
        if (c.shipped) exitance::formats::write_lightmap_exr(path, image, threads);
        else write_with(path, image, c.compression, c.zip_level, threads);
        write.push_back(seconds_since(start));
        write_cpu.push_back(cpu_seconds() - cpu_start);
        start = std::chrono::steady_clock::now();
        const exitance::formats::LightmapImage back = exitance::formats::read_lightmap_exr(path, threads);
        read.push_back(seconds_since(start));
        same = same && bit_identical(image, back);
      }
      const double bytes = double(std::filesystem::file_size(path));
      std::printf("| %s | %d | %.2f | %.2f | %.3f | %.3f | %.3f | %s |\n", c.name, threads, bytes / 1e6, raw / bytes, median(write),
                  median(write_cpu), median(read), same ? "yes" : "NO");
    }
  }
  std::filesystem::remove(path);
  return 0;
}
