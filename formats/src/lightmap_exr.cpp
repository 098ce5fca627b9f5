#include "exitance/formats/lightmap_exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>

#include <algorithm>
#include <stdexcept>
#include <thread>

namespace exitance::formats {

int lightmap_exr_threads() {
  static const int threads = [] {
    const int hardware = int(std::max(1u, std::thread::hardware_concurrency()));
    if (Imf::globalThreadCount() < hardware) Imf::setGlobalThreadCount(hardware);
    return hardware;
  }();
  return threads;
}

void write_lightmap_exr(const std::string& path, const LightmapImage& image, int threads) {
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    // zlib level 1: a third less CPU than OpenEXR 3.1's default 4 for 4-11 % larger files, the
    // same pixels (bench_exr_compression, bench/results/host-stages.md).
    header.zipCompressionLevel() = 1;
    header.insert("generator", Imf::StringAttribute("exitance"));
    Imf::FrameBuffer frame;
    for (const auto& [name, data] : image.channels) {
      if (data.size() != size_t(image.width) * size_t(image.height))
        throw std::runtime_error("channel " + name + " has the wrong size");
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      frame.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(data.data())), sizeof(float),
                                    sizeof(float) * size_t(image.width)));
    }
    Imf::OutputFile file(path.c_str(), header, threads < 0 ? lightmap_exr_threads() : threads);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
}

LightmapImage read_lightmap_exr(const std::string& path, int threads) {
  try {
    Imf::InputFile file(path.c_str(), threads < 0 ? lightmap_exr_threads() : threads);
    const Imath::Box2i window = file.header().dataWindow();
    LightmapImage image;
    image.width = window.max.x - window.min.x + 1;
    image.height = window.max.y - window.min.y + 1;
    Imf::FrameBuffer frame;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
      auto& data = image.channels[it.name()];
      data.assign(size_t(image.width) * size_t(image.height), 0.0f);
      char* base = reinterpret_cast<char*>(data.data()) -
                   (ptrdiff_t(window.min.x) + ptrdiff_t(window.min.y) * image.width) * ptrdiff_t(sizeof(float));
      frame.insert(it.name(), Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * size_t(image.width)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read " + path + ": " + e.what());
  }
}

}  // namespace exitance::formats
