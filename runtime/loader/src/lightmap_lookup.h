// Bilinear lookup of a lightmap page's R, G, B channels (or any one channel) at a page UV.
#pragma once
#include <string>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/loader/lookup_results.h"

namespace exitance::loader {

// Page UV (0,0) is the top-left corner of the first row; texel (i, j) has its centre at
// ((i + 0.5) / width, (j + 0.5) / height); outside the outer texel centres the edge texels are
// repeated (clamp to edge). The image must hold R, G, B of width * height floats each, and u, v
// must be finite (Bundle::open and Bundle::lightmap check both).
Rgb bilinear_page_rgb(const formats::LightmapImage& page, float u, float v);

// The same lookup of one channel (e.g. "error.Y"), which the page must hold.
float bilinear_page_channel(const formats::LightmapImage& page, const std::string& channel, float u, float v);

}  // namespace exitance::loader
