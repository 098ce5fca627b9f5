// Decodes glTF image bytes (PNG, JPEG, ...) through OpenImageIO into linear RGB.
#pragma once
#include <string>
#include <vector>

#include "exitance/runtime/scene.h"

namespace exitance {

// `name_hint` carries the extension OpenImageIO uses to pick a decoder ("x.png", "x.jpg").
// sRGB-encoded 8/16-bit data is converted to linear (glTF base colour and emissive textures are sRGB).
// Throws InputError(file, element, ...) when the bytes do not decode.
Texture decode_srgb_image(const std::vector<unsigned char>& bytes, const std::string& name_hint,
                          const std::string& file, const std::string& element);

// The same for data images (glTF normalTexture): 8/16-bit values mapped to [0, 1], no sRGB decode.
Texture decode_data_image(const std::vector<unsigned char>& bytes, const std::string& name_hint,
                          const std::string& file, const std::string& element);

// Reads an equirectangular float image (EXR/HDR) from disk for the sky: linear, no conversion.
Texture read_linear_image_file(const std::string& path, const std::string& element);

}  // namespace exitance
