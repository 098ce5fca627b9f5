#include "exitance/formats/lightmap_exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <stdexcept>

namespace exitance::formats {

void write_lightmap_exr(const std::string& path, const LightmapImage& image) {
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.insert("generator", Imf::StringAttribute("exitance"));
    Imf::FrameBuffer frame;
    for (const auto& [name, data] : image.channels) {
      if (data.size() != size_t(image.width) * size_t(image.height))
        throw std::runtime_error("channel " + name + " has the wrong size");
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      frame.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(data.data())), sizeof(float),
                                    sizeof(float) * size_t(image.width)));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
}

LightmapImage read_lightmap_exr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
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
