// --sky: the scene's sky radiance, a constant colour or an equirectangular image.
#pragma once
#include <string>

#include "exitance/runtime/scene.h"

namespace exitance {

// Parses --sky: "R,G,B" (three finite non-negative numbers) or an image file (EXR/HDR, read linear);
// "" = black. Throws InputError naming --sky.
Sky parse_sky_option(const std::string& value);

}  // namespace exitance
