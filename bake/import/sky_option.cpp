#include "exitance/bake/import/sky_option.h"

#include <cmath>
#include <sstream>
#include <vector>

#include "exitance/bake/import/image_decode.h"
#include "exitance/bake/input_error.h"

namespace exitance {

Sky parse_sky_option(const std::string& value) {
  Sky sky;
  if (value.empty()) return sky;
  std::stringstream stream(value);
  std::string part;
  std::vector<float> numbers;
  bool all_numbers = true;
  while (std::getline(stream, part, ',')) {
    try {
      size_t used = 0;
      const float v = std::stof(part, &used);
      if (used != part.size()) all_numbers = false;
      numbers.push_back(v);
    } catch (...) {
      all_numbers = false;
    }
  }
  if (all_numbers && numbers.size() == 3) {
    for (float v : numbers)
      if (!std::isfinite(v) || v < 0) throw InputError(value, "--sky", "colour components must be finite and >= 0");
    sky.constant = {numbers[0], numbers[1], numbers[2]};
    return sky;
  }
  if (all_numbers) throw InputError(value, "--sky", "expected R,G,B or an image file");
  sky.environment = read_linear_image_file(value, "--sky");
  return sky;
}

}  // namespace exitance
