#include "engine_options.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <vector>

namespace engine_sample {

const char* const kUsage =
    "usage: exitance_engine_sample SCENE.gltf BUNDLE LIGHT FROM_X,Y,Z TO_X,Y,Z --look-from X,Y,Z --look-at X,Y,Z "
    "--yfov RADIANS [--up X,Y,Z] [--size W,H] [--frames N] [--samples S] [--exposure EV] -o STRIP.png";

const char* const kHelp =
    "Renders SCENE.gltf lightmapped from BUNDLE (bake's output for it) with Vulkan on its own device, which it\n"
    "hands to the Exitance runtime. Frame 0 shows the baked lightmap (no edit); frames 1..N-1 move LIGHT's node\n"
    "from FROM to TO (frame k at t = k/(N-1)), refresh the lightmap (at most S samples per texel per frame) and\n"
    "sample the runtime's page images directly on the device. The frames are written side by side, tone-mapped\n"
    "as exitance-view's PNGs, to STRIP.png.\n"
    "\n"
    "  LIGHT            a KHR_lights_punctual light's name, or the name of the node placing it; FROM and TO\n"
    "                   are that node's local translation (its world position when it is a root node)\n"
    "  --look-from, --look-at, --yfov, --up   the pinhole camera, as exitance-view's (docs/view.md)\n"
    "  --size W,H       image size of one frame (default 320,240)\n"
    "  --frames N       frames, 1..1000 (default 4)\n"
    "  --samples S      samples per texel each refresh adds, 1..65536 (default 8)\n"
    "  --exposure EV    the linear values are multiplied by 2^EV before the tone curve (default 0)\n"
    "\n"
    "Materials are glTF factors only: albedo = baseColorFactor x (1 - metallicFactor), emission =\n"
    "emissiveFactor x KHR_materials_emissive_strength; textures, vertex colours and alpha modes are not read.\n"
    "Lightmap UVs are the glTF's TEXCOORD_1 (bake's default --uv 1). Instances without a lightmap show their\n"
    "emission only (an engine would light them from the bundle's probes), and a miss is black (no sky).\n"
    "Exit status: 0 written, 2 bad input, 1 a runtime, Vulkan or validation failure.\n";

namespace {

double parse_number(const std::string& option, const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value))
    throw UsageError(option + ": '" + text + "' is not a finite number");
  return value;
}

uint32_t parse_count(const std::string& option, const std::string& text, uint32_t low, uint32_t high) {
  const double value = parse_number(option, text);
  if (value != std::floor(value) || value < low || value > high)
    throw UsageError(option + ": '" + text + "' is not an integer in " + std::to_string(low) + ".." +
                     std::to_string(high));
  return uint32_t(value);
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts(1);
  for (char c : text) {
    if (c == ',')
      parts.emplace_back();
    else
      parts.back() += c;
  }
  return parts;
}

std::array<double, 3> parse_point(const std::string& option, const std::string& text) {
  const std::vector<std::string> parts = split_commas(text);
  if (parts.size() != 3) throw UsageError(option + ": '" + text + "' is not X,Y,Z");
  return {parse_number(option, parts[0]), parse_number(option, parts[1]), parse_number(option, parts[2])};
}

bool ends_with_png(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png";
}

}  // namespace

bool parse_engine_options(int argc, char** argv, EngineOptions& options) {
  std::vector<std::string> positional;
  bool look_from = false, look_at = false, yfov = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") return false;
    if (arg.size() < 2 || arg[0] != '-' || (arg[1] >= '0' && arg[1] <= '9') || arg[1] == '.') {
      positional.push_back(arg);  // negative coordinates ("-0.5,1,2") are positional values, not options
      continue;
    }
    if (i + 1 >= argc) throw UsageError(arg + ": needs a value");
    const std::string value = argv[++i];
    if (arg == "--look-from")
      options.look_from = parse_point(arg, value), look_from = true;
    else if (arg == "--look-at")
      options.look_at = parse_point(arg, value), look_at = true;
    else if (arg == "--up")
      options.up = parse_point(arg, value);
    else if (arg == "--yfov") {
      options.yfov = parse_number(arg, value), yfov = true;
      if (!(options.yfov > 0 && options.yfov < std::numbers::pi))
        throw UsageError(arg + ": " + value + " is not within (0, pi)");
    } else if (arg == "--size") {
      const std::vector<std::string> parts = split_commas(value);
      if (parts.size() != 2) throw UsageError(arg + ": '" + value + "' is not W,H");
      options.width = parse_count(arg, parts[0], 1, 16384);
      options.height = parse_count(arg, parts[1], 1, 16384);
    } else if (arg == "--frames")
      options.frames = parse_count(arg, value, 1, 1000);
    else if (arg == "--samples")
      options.samples = parse_count(arg, value, 1, 65536);
    else if (arg == "--exposure") {
      const double ev = parse_number(arg, value);
      if (std::fabs(ev) > 64) throw UsageError(arg + ": " + value + " is outside -64..64");
      options.exposure = float(ev);
    } else if (arg == "-o" || arg == "--out")
      options.output = value;
    else
      throw UsageError(arg + ": unknown option");
  }
  if (positional.size() != 5)
    throw UsageError("expected 5 arguments SCENE.gltf BUNDLE LIGHT FROM_X,Y,Z TO_X,Y,Z, got " +
                     std::to_string(positional.size()));
  options.gltf = positional[0];
  options.bundle = positional[1];
  options.light = positional[2];
  options.from = parse_point("FROM", positional[3]);
  options.to = parse_point("TO", positional[4]);
  if (!look_from) throw UsageError("--look-from: is required");
  if (!look_at) throw UsageError("--look-at: is required");
  if (!yfov) throw UsageError("--yfov: is required");
  if (options.output.empty()) throw UsageError("-o: is required");
  if (!ends_with_png(options.output)) throw UsageError("-o: " + options.output + ": the strip is written as .png");
  const uint64_t strip_pixels = uint64_t(options.width) * options.frames * options.height;
  if (strip_pixels > (uint64_t(1) << 28))
    throw UsageError("--size/--frames: a strip of " + std::to_string(strip_pixels) +
                     " pixels is too large (at most 2^28)");
  return true;
}

}  // namespace engine_sample
