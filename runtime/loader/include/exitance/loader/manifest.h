// manifest.json of a bundle (DESIGN §4, docs/bundle.md), the fields the loader uses. Parsing checks
// every one of them for presence, type and range and throws formats::FormatError naming the field
// ("manifest.json: instances[3].page: 7 is not a page (2 pages)"); unknown fields are ignored.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace exitance::loader {

constexpr uint32_t kManifestFormatVersion = 1;

struct PageInfo {
  std::string file;  // relative to the bundle folder, e.g. "lightmap-0.exr"
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<std::string> channels;
};

struct InstanceInfo {
  uint32_t node = 0;  // glTF node index
  std::string name;
  uint32_t mesh = 0;  // glTF mesh index
  uint32_t page = 0;  // index into Manifest::pages
  std::array<float, 4> scale_offset{1, 1, 0, 0};  // page UV = TEXCOORD_1 * (sx, sy) + (ox, oy)
  std::optional<std::array<uint32_t, 4>> rect;     // texel rectangle x, y, width, height, if written
};

struct ProbeGridInfo {
  std::string file;
  std::array<float, 3> origin{0, 0, 0};
  std::array<float, 3> spacing{1, 1, 1};
  std::array<uint32_t, 3> counts{0, 0, 0};
  uint32_t sh_order = 2;
};

struct SvoInfo {
  std::string file;
  std::array<float, 3> bounds_min{0, 0, 0};  // the octree's cube
  std::array<float, 3> bounds_max{0, 0, 0};
  uint32_t depth = 0;
};

struct Manifest {
  uint32_t format_version = kManifestFormatVersion;
  std::string generator;  // "" when absent
  std::vector<PageInfo> pages;
  std::vector<InstanceInfo> instances;
  std::optional<ProbeGridInfo> probes;
  std::optional<SvoInfo> svo;
};

// name_for_errors prefixes every message (normally the manifest's path).
Manifest parse_manifest(std::string_view json_text, const std::string& name_for_errors);

}  // namespace exitance::loader
