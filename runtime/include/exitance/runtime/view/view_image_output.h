// Writing a view: OpenEXR keeps linear radiance (R, G, B float); PNG is for people: exposure,
// a tone curve and sRGB encoding to 8 bits (docs/view.md, "PNG tone mapping").
#pragma once
#include <array>
#include <cstdint>
#include <string>

#include "exitance/runtime/vec_math.h"
#include "exitance/runtime/view/view_render.h"

namespace exitance::view {

enum class ViewImageFormat { Exr, Png };

// From the file name's extension (.exr or .png, any case). Throws ViewInputError naming -o otherwise.
ViewImageFormat view_image_format(const std::string& path);

// Checks before rendering that `path` can be written (its folder exists and accepts a file), so a
// bad -o fails in milliseconds; throws ViewInputError naming the file. Leaves nothing behind.
void check_view_output_writable(const std::string& path);

// PNG pixel: c * 2^exposure_ev, then x / (1 + Y) with Y the Rec. 709 luminance of that (a
// Reinhard curve on luminance, which keeps hue), clamped to [0, 1], sRGB-encoded, rounded to 8 bits.
std::array<uint8_t, 3> tone_map_to_srgb8(Vec3 linear, float exposure_ev);

// Writes the image through a temporary file in the same folder renamed at the end, so a failed
// write leaves no file at `path`. Throws ViewInputError naming the file on failure.
void write_view_image(const std::string& path, const ViewImage& image, float exposure_ev);

}  // namespace exitance::view
