// The sample's command line: what to load, where the camera is, how the light moves, what to write.
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace engine_sample {

// Bad input on the command line, or a scene or bundle the sample cannot use: exit status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct EngineOptions {
  std::string gltf;                    // the scene the bundle was baked from (geometry and materials come from it)
  std::string bundle;                  // the bundle bake wrote from it
  std::string light;                   // a KHR_lights_punctual light's name, or the name of the node placing it
  std::array<double, 3> from{}, to{};  // the light node's local translation, first and last frame
  std::array<double, 3> look_from{}, look_at{}, up{0, 1, 0};
  double yfov = 0;
  uint32_t width = 320, height = 240;
  uint32_t frames = 4;
  uint32_t samples = 8;  // refresh's cap on samples per texel, per frame
  float exposure = 0;
  std::string output;  // .png
};

// One line for errors and the first line of --help.
extern const char* const kUsage;
// The whole --help text.
extern const char* const kHelp;

// Throws UsageError naming the option and the problem. Returns false for --help (printed by main).
bool parse_engine_options(int argc, char** argv, EngineOptions& options);

}  // namespace engine_sample
