#include "exitance/formats/lightmap_exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
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
