// The frames side by side in one image, tone-mapped as exitance-view writes its PNGs, and written
// as a PNG (stb_image_write) under a temporary name renamed at the end.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace engine_sample {

class PngStrip {
 public:
  PngStrip(uint32_t frame_width, uint32_t frame_height, uint32_t frames, float exposure_ev);
  // `rgba`: one frame's linear RGBA floats, row 0 at the top.
  void put_frame(uint32_t frame, const std::vector<float>& rgba);
  // Throws std::runtime_error when the file cannot be written; no file is left behind then.
  void write(const std::string& path) const;

 private:
  uint32_t width_, height_, frames_;
  float exposure_;
  std::vector<uint8_t> rgb_;  // (frames x width) x height, 8-bit sRGB
};

}  // namespace engine_sample
