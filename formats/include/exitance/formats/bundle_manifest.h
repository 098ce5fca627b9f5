// manifest.json of a bundle (DESIGN §4, docs/bundle.md): its schema as types, one reader and one
// writer. bake and exitance-relight write it through write_bundle_manifest; the loader and
// exitance-relight read it through parse_bundle_manifest.
//
// The reader checks every field it knows for presence, type and range and throws FormatError
// naming the field ("manifest.json: instances[3].page: 7 is not a page (2 pages)"); unknown fields
// are ignored, so a newer writer's additions do not break an older reader. The writer runs the
// reader over what it wrote before returning, so a manifest that was written can always be read.
//
// Free-form blocks that no reader interprets ("stats", "relight") are carried as JSON text, which
// keeps this header free of any JSON library (it is installed with the loader).
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace exitance::formats {

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
  uint32_t page = 0;  // index into BundleManifest::pages
  std::array<float, 4> scale_offset{1, 1, 0, 0};  // page UV = TEXCOORD_1 * (sx, sy) + (ox, oy)
  std::optional<std::array<uint32_t, 4>> rect;     // texel rectangle x, y, width, height, if written
};

// How many probes placement kept, moved, refused and skipped (written by bake; optional).
struct ProbePlacementCounts {
  uint64_t valid = 0, moved = 0, invalid = 0, skipped = 0;
};

struct ProbeGridInfo {
  std::string file;
  std::array<float, 3> origin{0, 0, 0};
  std::array<float, 3> spacing{1, 1, 1};
  std::array<uint32_t, 3> counts{0, 0, 0};
  uint32_t sh_order = 2;
  std::optional<ProbePlacementCounts> placement;
};

struct SvoInfo {
  std::string file;
  std::array<float, 3> bounds_min{0, 0, 0};  // the octree's cube
  std::array<float, 3> bounds_max{0, 0, 0};
  uint32_t depth = 0;
  uint64_t nodes = 0;     // 0 when not written
  std::string vdb;        // the OpenVDB export's file, "" when the bundle has none
  std::string vdb_note;   // why there is none (exitance-relight does not write it), or ""
};

// scene.bin (formats/scene_format.md): written, or why not.
struct SceneFileInfo {
  std::string file;  // "" when skipped
  uint32_t format_version = 0;
  uint64_t bytes = 0;
  std::string skipped;  // non-empty exactly when file is empty
};

// "preview" (bake --preview, docs/bundle.md): tone-mapped PNGs for people, never read by an engine.
struct PreviewViewInfo {
  std::string file;    // e.g. "preview/Camera.png"
  std::string camera;  // the glTF camera it shows, "" for the automatic view
  std::array<float, 3> look_from{0, 0, 0};
  std::array<float, 3> look_at{0, 0, -1};  // differs from look_from
  std::array<float, 3> up{0, 1, 0};
  float yfov = 1;  // radians, in (0, pi)
  uint32_t width = 0, height = 0;  // 1..16384
};

struct PreviewInfo {
  std::vector<std::string> pages;  // one PNG per atlas page, in page order
  std::vector<PreviewViewInfo> views;
  std::string views_skipped;  // why there are no views (no scene.bin), or ""
};

// "light_layers" (docs/bundle.md "Light layers"): E/pi split by the light it came from, for the
// runtime (an edit that only scales a light scales its layer). One OpenEXR file per page with
// channels "layer<k>.R/G/B" for the layers k that light some texel of the page (absent: 0). The
// layers are laid out as scene.bin lays them out when opened (exitance/common/light_layers.h): 0 the
// sky, 1..punctual the punctual lights, then the emissive materials; the runtime checks `count` and
// `punctual` against that layout.
constexpr uint32_t kMaxManifestLightLayers = 256;
struct LightLayersInfo {
  uint32_t count = 0;     // 1..kMaxManifestLightLayers
  uint32_t punctual = 0;  // below count
  std::vector<std::string> files;  // one per page, in page order
};

// The input the bundle was baked from.
struct InputInfo {
  std::string file;    // file name without folders
  std::string sha256;  // 64 lowercase hex digits
};

// "settings": the options as the bake's stages used them. Every field is optional on reading (a
// field that is absent keeps the default below, which is bake's own default); a field that is
// present must have the right type and range.
struct BakeSettings {
  std::string backend;  // "cpu" | "vulkan"; "" when absent
  std::string integrator = "path";  // "path" | "bounces" (bake --integrator)
  uint32_t spp = 128;
  double time_budget_seconds = 0;
  double target_error = 0;
  bool adaptive = false;  // samples planned per texel (bake --adaptive)
  std::string sampler = "sobol";  // "sobol" | "independent" (bake --sampler)
  std::string first_bounce = "traced";  // "traced" | "cached" (bake --first-bounce; bounces mode)
  std::string directional = "off";  // "off" | "sh1" (bake --directional; written only when "sh1")
  int32_t bounces = -1;  // -1: until Russian roulette
  uint64_t seed = 0;
  double texel_density = 0;
  uint32_t max_page = 2048;
  uint32_t padding = 2;
  uint32_t lightmap_uv = 1;                   // the TEXCOORD set read where a mesh has it
  bool lightmap_uv_generate = false;          // --uv generate: written as "lightmap_uv": "generate"
  std::vector<uint32_t> generated_uv_meshes;  // glTF meshes whose lightmap UVs bake generated
  int32_t russian_roulette_start = 3;
  int32_t safety_bounce_cap = 4096;
  std::string sky;                       // as --sky gave it; "" = black
  std::optional<float> probe_spacing;    // absent: --probes none
  uint32_t probe_spp = 512;
  float probe_dering_window = 0;
  std::optional<uint32_t> voxel_resolution;  // absent: --voxel-resolution none
};

struct BundleManifest {
  uint32_t format_version = kManifestFormatVersion;
  std::string generator;  // "" when absent
  std::optional<InputInfo> input;
  std::optional<BakeSettings> settings;
  std::vector<PageInfo> pages;
  std::vector<InstanceInfo> instances;
  std::optional<ProbeGridInfo> probes;
  std::optional<SvoInfo> svo;
  std::optional<SceneFileInfo> scene;
  std::optional<PreviewInfo> preview;
  std::optional<LightLayersInfo> light_layers;
  std::string stats_json;    // "stats": a JSON object as text, "" when absent
  std::string relight_json;  // "relight": a JSON object as text, "" when absent

  // True when some page has per-bounce layers (channels "bounce<k>.R" ...).
  bool has_bounce_layers() const;
};

// name_for_errors prefixes every message (normally the manifest's path).
BundleManifest parse_bundle_manifest(std::string_view json_text, const std::string& name_for_errors);

// The manifest as JSON text (2-space indented, trailing newline) with the fixed "units" block.
// Throws FormatError, naming the field, when `manifest` would not pass parse_bundle_manifest or a
// free-form block is not a JSON object.
std::string write_bundle_manifest(const BundleManifest& manifest);

}  // namespace exitance::formats
